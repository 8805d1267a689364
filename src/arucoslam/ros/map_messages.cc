#include "arucoslam/ros/map_messages.h"

#include <cstring>

#include "arucoslam/ros/pose_messages.h"

namespace arucoslam {
namespace {

constexpr double kMarkerThicknessM = 0.01;

sensor_msgs::PointField FloatField(const std::string& name, std::uint32_t offset) {
  sensor_msgs::PointField field;
  field.name = name;
  field.offset = offset;
  field.datatype = sensor_msgs::PointField::FLOAT32;
  field.count = 1;
  return field;
}

std_msgs::ColorRGBA Colour(float r, float g, float b) {
  std_msgs::ColorRGBA colour;
  colour.r = r;
  colour.g = g;
  colour.b = b;
  colour.a = 1.0f;
  return colour;
}

}  // namespace

sensor_msgs::PointCloud2 PointCloudMessage(const std::vector<Eigen::Vector3d>& points,
                                           const ros::Time& stamp, const std::string& frame) {
  static_assert(sizeof(float) == 4, "float32 fields");
  sensor_msgs::PointCloud2 cloud;
  cloud.header.stamp = stamp;
  cloud.header.frame_id = frame;
  cloud.height = 1;
  cloud.width = static_cast<std::uint32_t>(points.size());
  cloud.fields = {FloatField("x", 0), FloatField("y", 4), FloatField("z", 8)};
  cloud.is_bigendian = false;  // the x86-64 and ARM hosts this runs on are little-endian
  cloud.point_step = 12;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_dense = true;
  cloud.data.resize(cloud.row_step);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const float xyz[3] = {static_cast<float>(points[i].x()), static_cast<float>(points[i].y()),
                          static_cast<float>(points[i].z())};
    std::memcpy(cloud.data.data() + i * cloud.point_step, xyz, sizeof(xyz));
  }
  return cloud;
}

visualization_msgs::MarkerArray MarkerArrayMessage(const MarkerMap& markers,
                                                   const ros::Time& stamp,
                                                   const std::string& frame) {
  visualization_msgs::MarkerArray array;
  visualization_msgs::Marker clear;
  clear.header.stamp = stamp;
  clear.header.frame_id = frame;
  clear.action = visualization_msgs::Marker::DELETEALL;
  array.markers.push_back(clear);
  for (const auto& [id, marker] : markers.markers) {
    visualization_msgs::Marker square;
    square.header.stamp = stamp;
    square.header.frame_id = frame;
    square.ns = "markers";
    square.id = id;
    square.type = visualization_msgs::Marker::CUBE;
    square.action = visualization_msgs::Marker::ADD;
    square.pose = PoseMessage(marker.world_from_marker);
    square.scale.x = marker.size;
    square.scale.y = marker.size;
    square.scale.z = kMarkerThicknessM;
    square.color = marker.fixed ? Colour(0.1f, 0.3f, 0.9f) : Colour(1.0f, 0.55f, 0.0f);
    array.markers.push_back(square);

    visualization_msgs::Marker label = square;
    label.ns = "marker_ids";
    label.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    // Just in front of the printed face (the marker's +z).
    label.pose = PoseMessage(marker.world_from_marker *
                             Rigid3(Eigen::Quaterniond::Identity(),
                                    Eigen::Vector3d(0.0, 0.0, 2.0 * kMarkerThicknessM)));
    label.scale.x = label.scale.y = 0.0;
    label.scale.z = std::max(0.05, 0.5 * marker.size);  // text height
    label.color = Colour(1.0f, 1.0f, 1.0f);
    label.text = std::to_string(id);
    array.markers.push_back(label);
  }
  return array;
}

}  // namespace arucoslam
