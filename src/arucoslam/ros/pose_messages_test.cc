#include "arucoslam/ros/pose_messages.h"

#include <gtest/gtest.h>

#include <map>

namespace arucoslam {
namespace {

Rigid3 SomePose() {
  return Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
                Eigen::Vector3d(4.0, -1.5, 0.8));
}

TEST(PoseMessagesTest, TransformCarriesParentFromChild) {
  const Rigid3 world_from_cam = SomePose();
  const geometry_msgs::TransformStamped message =
      TransformMessage(world_from_cam, ros::Time(12, 345), "world", "camera");
  EXPECT_EQ(message.header.frame_id, "world");
  EXPECT_EQ(message.child_frame_id, "camera");
  EXPECT_EQ(message.header.stamp, ros::Time(12, 345));
  const Eigen::Quaterniond rotation(message.transform.rotation.w, message.transform.rotation.x,
                                    message.transform.rotation.y, message.transform.rotation.z);
  const Eigen::Vector3d translation(message.transform.translation.x,
                                    message.transform.translation.y,
                                    message.transform.translation.z);
  // The camera's origin in the world is the transform's translation; a point in the camera
  // frame maps into the world with the rotation plus that translation.
  const Eigen::Vector3d p_in_cam(0.3, -0.2, 2.0);
  EXPECT_LT((rotation * p_in_cam + translation - world_from_cam * p_in_cam).norm(), 1e-12);
  EXPECT_NEAR(rotation.norm(), 1.0, 1e-12);
}

TEST(PoseMessagesTest, CovarianceIsDiagonalRowMajor) {
  const boost::array<double, 36> covariance = PoseCovariance(0.02, 0.01);
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) {
      const double expected = r != c ? 0.0 : (r < 3 ? 0.02 * 0.02 : 0.01 * 0.01);
      EXPECT_DOUBLE_EQ(covariance[r * 6 + c], expected) << r << "," << c;
    }
  }
  const geometry_msgs::PoseWithCovarianceStamped pose =
      PoseWithCovarianceMessage(SomePose(), covariance, ros::Time(1, 0), "world");
  EXPECT_EQ(pose.header.frame_id, "world");
  EXPECT_DOUBLE_EQ(pose.pose.pose.position.x, 4.0);
  EXPECT_DOUBLE_EQ(pose.pose.covariance[35], 1e-4);
}

TEST(PoseMessagesTest, StatusSaysStateAndFlags) {
  FrameStatus status;
  status.state = "tracking";
  status.has_pose = true;
  status.relocalised = true;
  status.world_aligned = true;
  status.num_markers = 2;
  status.num_keyframes = 14;
  status.num_map_points = 1200;
  diagnostic_msgs::DiagnosticArray message = StatusMessage(status, ros::Time(3, 0), "arucoslam");
  ASSERT_EQ(message.status.size(), 1u);
  EXPECT_EQ(message.header.stamp, ros::Time(3, 0));
  EXPECT_EQ(message.status[0].level, diagnostic_msgs::DiagnosticStatus::OK);
  EXPECT_EQ(message.status[0].message, "tracking");
  std::map<std::string, std::string> values;
  for (const diagnostic_msgs::KeyValue& entry : message.status[0].values) values[entry.key] = entry.value;
  EXPECT_EQ(values["relocalised"], "true");
  EXPECT_EQ(values["world_aligned"], "true");
  EXPECT_EQ(values["marker_pose"], "false");
  EXPECT_EQ(values["markers"], "2");
  EXPECT_EQ(values["map_points"], "1200");
  status.state = "lost";
  status.has_pose = false;
  message = StatusMessage(status, ros::Time(3, 0), "arucoslam");
  EXPECT_EQ(message.status[0].level, diagnostic_msgs::DiagnosticStatus::WARN);
}

}  // namespace
}  // namespace arucoslam
