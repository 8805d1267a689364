#include "arucoslam/ros/pose_messages.h"

namespace arucoslam {
namespace {

geometry_msgs::Quaternion QuaternionMessage(const Eigen::Quaterniond& rotation) {
  const Eigen::Quaterniond unit = rotation.normalized();
  geometry_msgs::Quaternion message;
  message.x = unit.x();
  message.y = unit.y();
  message.z = unit.z();
  message.w = unit.w();
  return message;
}

diagnostic_msgs::KeyValue KeyValue(const std::string& key, const std::string& value) {
  diagnostic_msgs::KeyValue entry;
  entry.key = key;
  entry.value = value;
  return entry;
}

std::string Flag(bool value) { return value ? "true" : "false"; }

}  // namespace

geometry_msgs::TransformStamped TransformMessage(const Rigid3& parent_from_child,
                                                 const ros::Time& stamp,
                                                 const std::string& parent_frame,
                                                 const std::string& child_frame) {
  geometry_msgs::TransformStamped message;
  message.header.stamp = stamp;
  message.header.frame_id = parent_frame;
  message.child_frame_id = child_frame;
  message.transform.translation.x = parent_from_child.translation.x();
  message.transform.translation.y = parent_from_child.translation.y();
  message.transform.translation.z = parent_from_child.translation.z();
  message.transform.rotation = QuaternionMessage(parent_from_child.rotation);
  return message;
}

geometry_msgs::Pose PoseMessage(const Rigid3& frame_from_body) {
  geometry_msgs::Pose pose;
  pose.position.x = frame_from_body.translation.x();
  pose.position.y = frame_from_body.translation.y();
  pose.position.z = frame_from_body.translation.z();
  pose.orientation = QuaternionMessage(frame_from_body.rotation);
  return pose;
}

boost::array<double, 36> PoseCovariance(double position_sigma_m, double rotation_sigma_rad) {
  boost::array<double, 36> covariance{};
  for (int i = 0; i < 6; ++i) {
    const double sigma = i < 3 ? position_sigma_m : rotation_sigma_rad;
    covariance[i * 6 + i] = sigma * sigma;
  }
  return covariance;
}

geometry_msgs::PoseWithCovarianceStamped PoseWithCovarianceMessage(
    const Rigid3& frame_from_body, const boost::array<double, 36>& covariance,
    const ros::Time& stamp, const std::string& frame) {
  geometry_msgs::PoseWithCovarianceStamped message;
  message.header.stamp = stamp;
  message.header.frame_id = frame;
  message.pose.pose = PoseMessage(frame_from_body);
  message.pose.covariance = covariance;
  return message;
}

diagnostic_msgs::DiagnosticArray StatusMessage(const FrameStatus& status, const ros::Time& stamp,
                                               const std::string& name) {
  diagnostic_msgs::DiagnosticStatus entry;
  entry.level = status.has_pose ? diagnostic_msgs::DiagnosticStatus::OK
                                : diagnostic_msgs::DiagnosticStatus::WARN;
  entry.name = name;
  entry.message = status.state;
  entry.values = {KeyValue("state", status.state),
                  KeyValue("pose", Flag(status.has_pose)),
                  KeyValue("relocalised", Flag(status.relocalised)),
                  KeyValue("world_aligned", Flag(status.world_aligned)),
                  KeyValue("marker_pose", Flag(status.marker_pose)),
                  KeyValue("markers", std::to_string(status.num_markers)),
                  KeyValue("keyframes", std::to_string(status.num_keyframes)),
                  KeyValue("map_points", std::to_string(status.num_map_points))};
  diagnostic_msgs::DiagnosticArray message;
  message.header.stamp = stamp;
  message.status.push_back(entry);
  return message;
}

}  // namespace arucoslam
