#include "arucoslam/ros/map_messages.h"

#include <gtest/gtest.h>

#include <cstring>

namespace arucoslam {
namespace {

TEST(MapMessagesTest, PointCloudPacksFloat32Xyz) {
  const std::vector<Eigen::Vector3d> points = {{1.0, 2.0, 3.0}, {-0.5, 0.25, 8.0}};
  const sensor_msgs::PointCloud2 cloud = PointCloudMessage(points, ros::Time(2, 0), "world");
  EXPECT_EQ(cloud.header.frame_id, "world");
  EXPECT_EQ(cloud.height, 1u);
  EXPECT_EQ(cloud.width, 2u);
  EXPECT_EQ(cloud.point_step, 12u);
  EXPECT_EQ(cloud.row_step, 24u);
  ASSERT_EQ(cloud.data.size(), 24u);
  ASSERT_EQ(cloud.fields.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(cloud.fields[i].name, std::string(1, "xyz"[i]));
    EXPECT_EQ(cloud.fields[i].offset, 4 * i);
    EXPECT_EQ(cloud.fields[i].datatype, sensor_msgs::PointField::FLOAT32);
    EXPECT_EQ(cloud.fields[i].count, 1u);
  }
  float xyz[3];
  std::memcpy(xyz, cloud.data.data() + 12, sizeof(xyz));
  EXPECT_EQ(xyz[0], -0.5f);
  EXPECT_EQ(xyz[1], 0.25f);
  EXPECT_EQ(xyz[2], 8.0f);
  EXPECT_EQ(PointCloudMessage({}, ros::Time(), "world").data.size(), 0u);
}

TEST(MapMessagesTest, MarkerArrayHasASquareAndALabelPerMarker) {
  MarkerMap map;
  MarkerInfo known;
  known.id = 7;
  known.size = 0.3;
  known.world_from_marker = Rigid3(Eigen::Quaterniond(0.5, 0.5, 0.5, 0.5), Eigen::Vector3d(4, 1.5, 0.8));
  map.markers[7] = known;
  MarkerInfo mapped = known;
  mapped.id = 9;
  mapped.fixed = false;
  map.markers[9] = mapped;
  const visualization_msgs::MarkerArray array = MarkerArrayMessage(map, ros::Time(1, 0), "world");
  ASSERT_EQ(array.markers.size(), 5u);
  EXPECT_EQ(array.markers[0].action, visualization_msgs::Marker::DELETEALL);
  const visualization_msgs::Marker& square = array.markers[1];
  EXPECT_EQ(square.ns, "markers");
  EXPECT_EQ(square.id, 7);
  EXPECT_EQ(square.type, visualization_msgs::Marker::CUBE);
  EXPECT_EQ(square.header.frame_id, "world");
  EXPECT_DOUBLE_EQ(square.scale.x, 0.3);
  EXPECT_DOUBLE_EQ(square.pose.position.x, 4.0);
  EXPECT_DOUBLE_EQ(square.pose.orientation.w, 0.5);
  EXPECT_EQ(array.markers[2].ns, "marker_ids");
  EXPECT_EQ(array.markers[2].text, "7");
  // The label sits in front of the face: the marker's +z is the world's +x here.
  EXPECT_GT(array.markers[2].pose.position.x, 4.0);
  EXPECT_NE(array.markers[3].color.r, square.color.r);  // mapped markers in another colour
}

}  // namespace
}  // namespace arucoslam
