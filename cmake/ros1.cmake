# ROS 1 from Debian 12's packages (libroscpp-dev, librosbag-storage-dev, libtf2-ros-dev,
# libimage-transport-dev and the message packages). Their CMake configs need catkin/ament
# Python modules and rosbag_storage.pc requires a pluginlib.pc that Debian does not ship, so
# headers and libraries are found directly. Defines the interface target arucoslam_ros1 and
# sets ARUCOSLAM_WITH_ROS; without ROS it prints one line and io/rosbag/ and ros/ are skipped.
option(ARUCOSLAM_ROS "Build the ROS 1 layer (bag input, arucoslam_ros node) when ROS is found" ON)
set(ARUCOSLAM_WITH_ROS OFF)
if(ARUCOSLAM_ROS)
  set(_ros_missing "")
  set(_ros_include_dirs "")
  # Header -> folder that must be on the include path (pluginlib and friends nest one deeper).
  foreach(_entry
      "ros/ros.h|" "rosbag/bag.h|" "tf2_ros/transform_broadcaster.h|"
      "image_transport/image_transport.h|" "sensor_msgs/Image.h|" "geometry_msgs/PoseWithCovarianceStamped.h|"
      "nav_msgs/Path.h|" "visualization_msgs/MarkerArray.h|" "diagnostic_msgs/DiagnosticArray.h|"
      "tf2_msgs/TFMessage.h|" "pluginlib/class_loader.hpp|pluginlib"
      "class_loader/class_loader.hpp|class_loader" "rcpputils/shared_library.hpp|rcpputils"
      "rcutils/types.h|rcutils" "ament_index_cpp/get_resource.hpp|ament_index_cpp")
    string(REPLACE "|" ";" _pair "${_entry}")
    list(GET _pair 0 _header)
    list(GET _pair 1 _suffix)
    string(MAKE_C_IDENTIFIER "ROS1_INCLUDE_${_header}" _var)
    find_path(${_var} ${_header} PATH_SUFFIXES ${_suffix})
    if(${_var})
      list(APPEND _ros_include_dirs ${${_var}})
    else()
      list(APPEND _ros_missing ${_header})
    endif()
  endforeach()
  set(_ros_libraries "")
  foreach(_lib roscpp rosconsole roscpp_serialization rostime cpp_common xmlrpcpp rosbag_storage
               roslz4 tf2_ros tf2 image_transport class_loader console_bridge boost_system)
    find_library(ROS1_LIBRARY_${_lib} ${_lib})
    if(ROS1_LIBRARY_${_lib})
      list(APPEND _ros_libraries ${ROS1_LIBRARY_${_lib}})
    else()
      list(APPEND _ros_missing lib${_lib})
    endif()
  endforeach()
  find_program(ROS1_MASTER_PROGRAM rosmaster)
  find_program(ROS1_LAUNCH_PROGRAM roslaunch)
  if(_ros_missing)
    list(JOIN _ros_missing ", " _ros_missing_text)
    message(STATUS "ROS 1 not found (missing ${_ros_missing_text}): skipping io/rosbag/, "
                   "the ros/ layer and the arucoslam_ros node (scripts/install-deps.sh installs them)")
  else()
    list(REMOVE_DUPLICATES _ros_include_dirs)
    add_library(arucoslam_ros1 INTERFACE)
    target_include_directories(arucoslam_ros1 SYSTEM INTERFACE ${_ros_include_dirs})
    target_link_libraries(arucoslam_ros1 INTERFACE ${_ros_libraries})
    set(ARUCOSLAM_WITH_ROS ON)
    message(STATUS "ROS 1 found: building io/rosbag/ (bag input) and the ros/ layer (arucoslam_ros node)")
  endif()
else()
  message(STATUS "ARUCOSLAM_ROS is OFF: skipping io/rosbag/ (bag input), the ros/ layer and the arucoslam_ros node")
endif()
