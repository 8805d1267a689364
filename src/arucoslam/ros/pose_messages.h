// ROS 1 messages of the node's pose outputs, as pure functions (tested without a roscore):
// a pose as a tf transform, a pose with its covariance, and the per-frame status.
#pragma once

#include <boost/array.hpp>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <ros/time.h>
#include <string>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/ros/frame_status.h"

namespace arucoslam {

// tf's parent -> child transform: `parent_from_child` maps child coordinates into the parent
// frame (ROS's convention: the transform's translation is the child's origin in the parent).
geometry_msgs::TransformStamped TransformMessage(const Rigid3& parent_from_child,
                                                 const ros::Time& stamp,
                                                 const std::string& parent_frame,
                                                 const std::string& child_frame);

geometry_msgs::Pose PoseMessage(const Rigid3& frame_from_body);

// Row-major 6x6 covariance of (x, y, z, rotation about x, y, z) with independent axes:
// position_sigma_m^2 on the first three diagonal entries, rotation_sigma_rad^2 on the last.
boost::array<double, 36> PoseCovariance(double position_sigma_m, double rotation_sigma_rad);

geometry_msgs::PoseWithCovarianceStamped PoseWithCovarianceMessage(
    const Rigid3& frame_from_body, const boost::array<double, 36>& covariance,
    const ros::Time& stamp, const std::string& frame);

// One DiagnosticStatus named `name`: level OK with a pose, WARN without (message: the state),
// and key-value pairs state, pose, relocalised, world_aligned, marker_pose, markers,
// keyframes, map_points ("true"/"false" and decimal numbers).
diagnostic_msgs::DiagnosticArray StatusMessage(const FrameStatus& status, const ros::Time& stamp,
                                               const std::string& name);

}  // namespace arucoslam
