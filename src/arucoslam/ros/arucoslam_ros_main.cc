// arucoslam_ros: the ROS 1 node. `rosrun`/`roslaunch` it with the image topic remapped to
// "image" and its camera_info to "camera_info" (ros/launch/arucoslam.launch); parameters in
// slam_node.h. A bad parameter or file is one line on stderr and exit status 2.
#include <glog/logging.h>
#include <ros/ros.h>

#include <cstdio>
#include <memory>

#include "arucoslam/ros/slam_node.h"
#include "arucoslam/util/error.h"

int main(int argc, char** argv) {
  google::InitGoogleLogging(argv[0]);
  FLAGS_minloglevel = google::GLOG_WARNING;  // Ceres' per-solve lines stay quiet
  ros::init(argc, argv, "arucoslam");
  try {
    ros::NodeHandle node;
    ros::NodeHandle private_node("~");
    arucoslam::SlamSessionOptions session_options;
    const arucoslam::SlamNodeParameters params =
        arucoslam::ReadSlamNodeParameters(private_node, &session_options);
    auto session = std::make_unique<arucoslam::SlamSession>(session_options);
    arucoslam::SlamNode slam_node(node, private_node, params, std::move(session));
    ROS_INFO("arucoslam_ros ready: %s -> tf %s -> %s", node.resolveName("image").c_str(),
             params.world_frame.c_str(),
             (params.base_frame.empty() ? params.camera_frame : params.base_frame).c_str());
    ros::spin();
  } catch (const arucoslam::InputError& error) {
    std::fprintf(stderr, "arucoslam_ros: %s\n", error.what());
    return 2;
  }
  return 0;
}
