// ROS 1 messages of the node's map outputs, as pure functions (tested without a roscore):
// map points as a sensor_msgs/PointCloud2 and the marker map as a MarkerArray for rviz.
#pragma once

#include <Eigen/Core>
#include <ros/time.h>
#include <sensor_msgs/PointCloud2.h>
#include <string>
#include <vector>
#include <visualization_msgs/MarkerArray.h>

#include "arucoslam/markers/marker_map.h"

namespace arucoslam {

// An unordered cloud (height 1) of float32 x, y, z fields, little-endian, 12 bytes a point.
sensor_msgs::PointCloud2 PointCloudMessage(const std::vector<Eigen::Vector3d>& points,
                                           const ros::Time& stamp, const std::string& frame);

// Per marker a thin CUBE at world_from_marker (side x side x 1 cm; fixed markers blue,
// mapped ones orange) in namespace "markers" and its id as TEXT_VIEW_FACING in "marker_ids",
// both with the marker's id; preceded by a DELETEALL so markers no longer in the map vanish.
visualization_msgs::MarkerArray MarkerArrayMessage(const MarkerMap& markers,
                                                   const ros::Time& stamp,
                                                   const std::string& frame);

}  // namespace arucoslam
