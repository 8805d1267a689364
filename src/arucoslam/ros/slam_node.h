// SlamNode: the ROS 1 node around a SlamSession. Images (image_transport, topic "image") and
// camera_info (topic "camera_info") arrive on ROS's callback thread and wait in a short queue;
// a worker thread runs the SLAM and publishes the camera pose through tf2, ~pose, ~path,
// ~status, ~map_points and ~markers. Parameters: see SlamNodeParameters and the launch file.
#pragma once

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <nav_msgs/Path.h>
#include <optional>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <string>
#include <thread>
#include <tf2_ros/transform_broadcaster.h>
#include <image_transport/image_transport.h>

#include "arucoslam/ros/slam_session.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct SlamNodeParameters {
  std::string world_frame = "world";   // parent of the published transform
  std::string camera_frame = "camera";  // the camera's optical frame (x right, y down, z ahead)
  // Non-empty: the transform published is world -> base_frame, from base_from_camera.
  std::string base_frame;
  Rigid3 base_from_camera;  // the camera's mounting on the base (param base_from_camera:
                            // [x, y, z, qx, qy, qz, qw])
  std::string camera_path;  // calibration file; empty: from the camera_info topic
  std::string image_transport = "raw";
  int queue_size = 2;              // images waiting for the SLAM; the oldest are dropped
  double map_period_s = 1.0;       // ~map_points every this many seconds of image time
  double position_sigma_m = 0.02;  // nominal standard deviations in ~pose's covariance
  double rotation_sigma_rad = 0.01;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("queue_size", queue_size, 1);
    check.AtLeast("map_period_s", map_period_s, 0.0);
    check.Above("position_sigma_m", position_sigma_m, 0.0);
    check.Above("rotation_sigma_rad", rotation_sigma_rad, 0.0);
    check.Require(!world_frame.empty(), "world_frame", "non-empty");
    check.Require(!camera_frame.empty(), "camera_frame", "non-empty");
    return check.ok();
  }
};

// Reads the node's parameters from `private_node` ("~"); throws InputError naming the
// parameter on a bad value. `session` receives the SLAM options (marker_map, vocabulary,
// num_features, loop_closing, blocking, live_source).
SlamNodeParameters ReadSlamNodeParameters(const ros::NodeHandle& private_node,
                                          SlamSessionOptions* session);

class SlamNode {
 public:
  SlamNode(ros::NodeHandle node, ros::NodeHandle private_node, const SlamNodeParameters& params,
           std::unique_ptr<SlamSession> session);
  ~SlamNode();  // stops the worker and finishes the SLAM
  SlamNode(const SlamNode&) = delete;
  SlamNode& operator=(const SlamNode&) = delete;

 private:
  struct QueuedImage {
    cv::Mat grey;
    ros::Time stamp;
  };
  void OnImage(const sensor_msgs::ImageConstPtr& image);
  void OnCameraInfo(const sensor_msgs::CameraInfoConstPtr& info);
  void Work();
  void ProcessImage(const QueuedImage& image);
  void Publish(const SlamUpdate& update, const ros::Time& stamp);
  void PublishMap(const ros::Time& stamp);

  SlamNodeParameters params_;
  std::unique_ptr<SlamSession> session_;
  ros::NodeHandle node_;
  image_transport::ImageTransport transport_;
  image_transport::Subscriber image_subscriber_;
  ros::Subscriber info_subscriber_;
  tf2_ros::TransformBroadcaster broadcaster_;
  ros::Publisher pose_publisher_, path_publisher_, status_publisher_, points_publisher_,
      markers_publisher_;
  nav_msgs::Path path_;
  std::optional<ros::Time> last_map_stamp_;
  std::optional<ros::Time> last_stamp_;

  std::mutex mutex_;  // guards the fields below
  std::condition_variable wake_;
  std::deque<QueuedImage> queue_;
  std::optional<CameraModel> camera_;
  bool stop_ = false;
  std::size_t num_dropped_ = 0;
  std::thread worker_;
};

}  // namespace arucoslam
