#include "arucoslam/ros/slam_node.h"

#include <utility>
#include <vector>

#include "arucoslam/io/calibration.h"
#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/io/rosbag/camera_info.h"
#include "arucoslam/io/rosbag/image_messages.h"
#include "arucoslam/ros/map_messages.h"
#include "arucoslam/ros/pose_messages.h"
#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

constexpr const char* kStatusName = "arucoslam";

Rigid3 ReadMounting(const ros::NodeHandle& node, const std::string& name) {
  std::vector<double> values;
  if (!node.getParam(name, values)) return Rigid3::Identity();
  if (values.size() != 7) {
    throw InputError("~" + name, "expected [x, y, z, qx, qy, qz, qw], got " +
                                     std::to_string(values.size()) + " numbers");
  }
  const Eigen::Quaterniond rotation(values[6], values[3], values[4], values[5]);
  if (!(rotation.norm() > 1e-9)) throw InputError("~" + name, "zero quaternion");
  return Rigid3(rotation, Eigen::Vector3d(values[0], values[1], values[2]));
}

}  // namespace

SlamNodeParameters ReadSlamNodeParameters(const ros::NodeHandle& private_node,
                                          SlamSessionOptions* session) {
  SlamNodeParameters params;
  private_node.param("world_frame", params.world_frame, params.world_frame);
  private_node.param("camera_frame", params.camera_frame, params.camera_frame);
  private_node.param("base_frame", params.base_frame, params.base_frame);
  params.base_from_camera = ReadMounting(private_node, "base_from_camera");
  private_node.param("camera", params.camera_path, params.camera_path);
  private_node.param("image_transport", params.image_transport, params.image_transport);
  private_node.param("queue_size", params.queue_size, params.queue_size);
  private_node.param("map_period", params.map_period_s, params.map_period_s);
  private_node.param("position_sigma", params.position_sigma_m, params.position_sigma_m);
  private_node.param("rotation_sigma", params.rotation_sigma_rad, params.rotation_sigma_rad);
  if (!params.Check()) {
    throw InputError("~", "bad parameter: queue_size >= 1, map_period >= 0, position_sigma > 0, "
                          "rotation_sigma > 0 and non-empty frame names expected");
  }
  std::string markers;
  private_node.param("markers", markers, std::string());
  if (!markers.empty()) session->marker_map = ReadMarkerMapJson(markers);
  std::string vocabulary;
  private_node.param("vocabulary", vocabulary, std::string());
  session->vocabulary = vocabulary;
  private_node.param("features", session->num_features, session->num_features);
  private_node.param("loop_closing", session->loop_closing, session->loop_closing);
  private_node.param("blocking", session->blocking, session->blocking);
  private_node.param("live_source", session->live_source, session->live_source);
  return params;
}

SlamNode::SlamNode(ros::NodeHandle node, ros::NodeHandle private_node,
                   const SlamNodeParameters& params, std::unique_ptr<SlamSession> session)
    : params_(params), session_(std::move(session)), node_(node), transport_(node) {
  if (!params_.camera_path.empty()) camera_ = ReadCameraModel(params_.camera_path);
  pose_publisher_ = private_node.advertise<geometry_msgs::PoseWithCovarianceStamped>("pose", 10);
  path_publisher_ = private_node.advertise<nav_msgs::Path>("path", 1, /*latch=*/true);
  status_publisher_ = private_node.advertise<diagnostic_msgs::DiagnosticArray>("status", 100);
  points_publisher_ = private_node.advertise<sensor_msgs::PointCloud2>("map_points", 1, true);
  markers_publisher_ =
      private_node.advertise<visualization_msgs::MarkerArray>("markers", 1, /*latch=*/true);
  markers_publisher_.publish(
      MarkerArrayMessage(session_->Markers(), ros::Time::now(), params_.world_frame));
  path_.header.frame_id = params_.world_frame;
  worker_ = std::thread([this] { Work(); });
  image_subscriber_ = transport_.subscribe("image", static_cast<std::uint32_t>(params_.queue_size),
                                           &SlamNode::OnImage, this,
                                           image_transport::TransportHints(params_.image_transport));
  if (!camera_) info_subscriber_ = node_.subscribe("camera_info", 1, &SlamNode::OnCameraInfo, this);
}

SlamNode::~SlamNode() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
  session_->Finish();
}

void SlamNode::OnImage(const sensor_msgs::ImageConstPtr& image) {
  QueuedImage queued;
  try {
    queued.grey = GreyFromImage(*image, image_subscriber_.getTopic());
  } catch (const InputError& error) {
    ROS_ERROR_THROTTLE(5.0, "%s", error.what());
    return;
  }
  queued.stamp = image->header.stamp;
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(std::move(queued));
    while (queue_.size() > static_cast<std::size_t>(params_.queue_size)) {
      queue_.pop_front();
      ++num_dropped_;
    }
  }
  wake_.notify_one();
}

void SlamNode::OnCameraInfo(const sensor_msgs::CameraInfoConstPtr& info) {
  {
    std::lock_guard lock(mutex_);
    if (camera_) return;
  }
  try {
    const CameraModel camera = CameraFromInfo(*info, info_subscriber_.getTopic());
    std::lock_guard lock(mutex_);
    camera_ = camera;
  } catch (const InputError& error) {
    ROS_ERROR_THROTTLE(5.0, "%s", error.what());
  }
}

void SlamNode::Work() {
  std::size_t reported_drops = 0;
  while (true) {
    QueuedImage image;
    std::optional<CameraModel> camera;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || !queue_.empty(); });
      if (stop_) return;
      image = std::move(queue_.front());
      queue_.pop_front();
      camera = camera_;
      if (num_dropped_ > reported_drops) {
        ROS_WARN_THROTTLE(5.0, "%zu images dropped so far: the SLAM is slower than the camera",
                          num_dropped_);
        reported_drops = num_dropped_;
      }
    }
    if (!session_->started()) {
      if (!camera) {
        ROS_WARN_THROTTLE(5.0, "waiting for camera_info on %s", info_subscriber_.getTopic().c_str());
        FrameStatus waiting;
        waiting.state = "waiting for camera";
        status_publisher_.publish(StatusMessage(waiting, image.stamp, kStatusName));
        continue;
      }
      session_->Start(*camera);
      ROS_INFO("camera %dx%d fx %.1f (%s distortion)", camera->width, camera->height,
               camera->fx, DistortionModelName(camera->model).c_str());
    }
    ProcessImage(image);
  }
}

void SlamNode::ProcessImage(const QueuedImage& image) {
  const CameraModel& camera = session_->camera();
  if (image.grey.cols != camera.width || image.grey.rows != camera.height) {
    ROS_ERROR_THROTTLE(5.0, "image is %dx%d, the camera's %dx%d: skipped", image.grey.cols,
                       image.grey.rows, camera.width, camera.height);
    return;
  }
  if (last_stamp_ && image.stamp <= *last_stamp_) {
    ROS_WARN_THROTTLE(5.0, "image stamp %.3f not after the previous one (%.3f): skipped",
                      image.stamp.toSec(), last_stamp_->toSec());
    return;
  }
  last_stamp_ = image.stamp;
  const double timestamp_s = 1e-9 * static_cast<double>(image.stamp.toNSec());
  Publish(session_->Process(image.grey, timestamp_s), image.stamp);
  if (!last_map_stamp_ || (image.stamp - *last_map_stamp_).toSec() >= params_.map_period_s) {
    PublishMap(image.stamp);
  }
}

void SlamNode::Publish(const SlamUpdate& update, const ros::Time& stamp) {
  if (update.world_from_cam) {
    const bool to_base = !params_.base_frame.empty();
    const Rigid3 world_from_child =
        to_base ? *update.world_from_cam * params_.base_from_camera.Inverse()
                : *update.world_from_cam;
    const std::string& child = to_base ? params_.base_frame : params_.camera_frame;
    broadcaster_.sendTransform(TransformMessage(world_from_child, stamp, params_.world_frame, child));
    pose_publisher_.publish(PoseWithCovarianceMessage(
        world_from_child, PoseCovariance(params_.position_sigma_m, params_.rotation_sigma_rad),
        stamp, params_.world_frame));
    geometry_msgs::PoseStamped pose;
    pose.header.stamp = stamp;
    pose.header.frame_id = params_.world_frame;
    pose.pose = PoseMessage(world_from_child);
    path_.header.stamp = stamp;
    path_.poses.push_back(pose);
    path_publisher_.publish(path_);
  }
  status_publisher_.publish(StatusMessage(update.status, stamp, kStatusName));
}

void SlamNode::PublishMap(const ros::Time& stamp) {
  last_map_stamp_ = stamp;
  points_publisher_.publish(PointCloudMessage(session_->MapPoints(), stamp, params_.world_frame));
}

}  // namespace arucoslam
