// ROS 1 end to end on a rendered factory sequence with markers written into a bag:
// `arucoslam run` on the bag gives the sequence's trajectory; the arucoslam_ros node, fed the
// bag's images and camera_info through its own rosmaster on loopback, publishes tf poses in
// the marker world within 1 cm of a threaded `run`'s ATE on the same frames, started by hand
// or by its launch file; bad bags are one line and exit status 2 with nothing written.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <ros/ros.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <tf2_msgs/TFMessage.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <algorithm>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "arucoslam/eval/association.h"
#include "arucoslam/eval/pose_error.h"
#include "arucoslam/exe/command_test_util.h"
#include "arucoslam/io/calibration.h"
#include "arucoslam/io/path_json.h"
#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/io/rosbag/camera_info.h"
#include "arucoslam/io/rosbag/image_messages.h"

extern char** environ;

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

using Outcome = testing_util::SplitCommandResult;

std::string ReadText(const fs::path& path) {
  std::ifstream stream(path);
  std::ostringstream text;
  text << stream.rdbuf();
  return text.str();
}

// One frame of the sequence: EuRoC stamp and image file.
struct SequenceFrame {
  std::int64_t stamp_ns = 0;
  fs::path image;
};

std::vector<SequenceFrame> ReadFrames(const fs::path& sequence) {
  std::ifstream csv(sequence / "mav0" / "cam0" / "data.csv");
  std::vector<SequenceFrame> frames;
  std::string line;
  while (std::getline(csv, line)) {
    if (line.empty() || line[0] == '#') continue;
    const std::size_t comma = line.find(',');
    SequenceFrame frame;
    frame.stamp_ns = std::stoll(line.substr(0, comma));
    std::string name = line.substr(comma + 1);
    while (!name.empty() && (name.back() == '\r' || name.back() == ' ')) name.pop_back();
    frame.image = sequence / "mav0" / "cam0" / "data" / name;
    frames.push_back(frame);
  }
  return frames;
}

ros::Time StampOf(std::int64_t stamp_ns) {
  ros::Time stamp;
  stamp.fromNSec(static_cast<std::uint64_t>(stamp_ns));
  return stamp;
}

// World ATE (no alignment: the markers give the world frame), RMS metres, and the number of
// poses matched to the ground truth.
std::pair<double, std::size_t> WorldAte(const Trajectory& truth, const Trajectory& estimate) {
  const AssociatedTrajectories pairs = AssociateByTime(truth, estimate, AssociationOptions{0.001});
  const std::vector<double> errors =
      AbsolutePoseErrors(pairs.gt, pairs.est, PoseRelation::kTranslation);
  double sum = 0.0;
  for (double error : errors) sum += error * error;
  return {errors.empty() ? 0.0 : std::sqrt(sum / errors.size()), errors.size()};
}

// A child process with stdout and stderr in `log`; ended by EndProcess.
pid_t StartProcess(const std::vector<std::string>& arguments, const fs::path& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::vector<char*> argv;
  for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int error = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return error == 0 ? pid : -1;
}

// SIGINT, then SIGKILL after `grace`; returns the exit status (-1: killed or not started).
int EndProcess(pid_t pid, std::chrono::seconds grace) {
  if (pid <= 0) return -1;
  kill(pid, SIGINT);
  const auto deadline = std::chrono::steady_clock::now() + grace;
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

int FreeLoopbackPort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  socklen_t length = sizeof(address);
  if (bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 ||
      getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    close(fd);
    return -1;
  }
  close(fd);
  return ntohs(address.sin_port);
}

// The node's run on the bag and what it is compared with.
struct NodeOutcome {
  std::size_t num_images = 0;
  std::size_t num_statuses = 0;
  Trajectory poses;  // tf world -> camera, one per frame stamp
};

// A rosmaster on a free loopback port and this process's roscpp, started once for the
// suite's node tests (roscpp cannot be initialised twice in one process).
class RosSession {
 public:
  static bool Start(const fs::path& dir) {
    if (master_ > 0) return true;
    const int port = FreeLoopbackPort();
    if (port <= 0) return false;
    const fs::path ros_home = dir / "ros_home";
    fs::create_directories(ros_home);
    const std::string master_uri = "http://127.0.0.1:" + std::to_string(port);
    setenv("ROS_MASTER_URI", master_uri.c_str(), 1);
    setenv("ROS_IP", "127.0.0.1", 1);
    setenv("ROS_HOSTNAME", "localhost", 1);
    setenv("ROS_HOME", ros_home.c_str(), 1);
    setenv("ROS_LOG_DIR", ros_home.c_str(), 1);
    master_ = StartProcess({ARUCOSLAM_ROSMASTER, "--core", "-p", std::to_string(port)},
                           dir / "rosmaster.log");
    if (master_ <= 0) return false;
    ros::M_string remappings;
    ros::init(remappings, "arucoslam_bag_player",
              ros::init_options::AnonymousName | ros::init_options::NoSigintHandler);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (!ros::master::check() && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return ros::master::check();
  }
  static void Stop() {
    if (master_ <= 0) return;
    ros::shutdown();
    EndProcess(master_, std::chrono::seconds(10));
    master_ = -1;
  }

 private:
  static pid_t master_;
};

pid_t RosSession::master_ = -1;

class BagEndToEndTest : public ::testing::Test {
 protected:
  // A one-aisle factory with 0.3 m markers at its docks, driven from x = 6 m to 10.5 m at
  // 15 Hz, 320x240 (about 90 frames); the bag holds its images (mono8) on /cam/image_raw and
  // its camera on /cam/camera_info, stamped with the sequence's nanoseconds.
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("arucoslam_bag_e2e_test_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    Outcome made = Run("world factory --seed 3 --aisles 1 --aisle-length 8 --wall-markers 0 "
                       "--markers-per-dock 4 "
                       "--marker-size 0.3 --out " + (dir_ / "world").string());
    ASSERT_EQ(made.status, 0) << made.err;
    CameraModel camera = PinholeCamera(320, 240, 230.0);
    WriteEuRoCSensorYaml(camera, dir_ / "camera.yaml");
    PathSpec spec = ReadPathJson(dir_ / "world" / "path.json");
    spec.options.camera_rate_hz = 15.0;
    spec.waypoints = {{6.0, 4.6, 0.0}, {10.5, 4.6, 0.0}};
    WritePathJson(dir_ / "path.json", spec);
    made = Run("simulate --world " + (dir_ / "world" / "world.sdf").string() + " --path " +
               (dir_ / "path.json").string() + " --camera " + (dir_ / "camera.yaml").string() +
               " --msaa 1 --quiet --out " + Sequence().string());
    ASSERT_EQ(made.status, 0) << made.err;
    WriteBag(Bag(), /*with_camera_info=*/true);
  }
  static void TearDownTestSuite() {
    RosSession::Stop();
    fs::remove_all(dir_);
  }

  // Plays the bag's messages in order into the running node (started as `node_pid`, logging
  // to `log`), each image once the node reported the one before; ends the node with SIGINT.
  static void PlayBagIntoNode(pid_t node_pid, const fs::path& log, NodeOutcome* outcome);
  // The node's tf poses against a threaded `run` on the same bag (run once for the suite).
  static void CompareWithRun(const NodeOutcome& node);

  static fs::path Sequence() { return dir_ / "seq"; }
  static fs::path Bag() { return dir_ / "seq.bag"; }
  static fs::path Markers() { return Sequence() / "markers.json"; }
  static Trajectory Truth() {
    return ReadEurocTrajectory(Sequence() / "mav0" / "state_groundtruth_estimate0" / "data.csv");
  }

  static void WriteBag(const fs::path& path, bool with_camera_info) {
    const sensor_msgs::CameraInfo info =
        CameraInfoFromModel(ReadCameraModel(Sequence() / "mav0" / "cam0" / "sensor.yaml"));
    rosbag::Bag bag(path.string(), rosbag::bagmode::Write);
    for (const SequenceFrame& frame : ReadFrames(Sequence())) {
      const ros::Time stamp = StampOf(frame.stamp_ns);
      sensor_msgs::Image image = ImageMessageFromGrey(cv::imread(frame.image.string(), cv::IMREAD_GRAYSCALE));
      image.header.stamp = stamp;
      image.header.frame_id = "camera";
      bag.write("/cam/image_raw", stamp, image);
      if (with_camera_info) {
        sensor_msgs::CameraInfo stamped = info;
        stamped.header = image.header;
        bag.write("/cam/camera_info", stamp, stamped);
      }
    }
  }

  static Outcome Run(const std::string& arguments) {
    return testing_util::RunArucoslamSplit(arguments, dir_);
  }

  static fs::path dir_;
};

fs::path BagEndToEndTest::dir_;

TEST_F(BagEndToEndTest, RunOnTheBagGivesTheSequencesTrajectory) {
  const std::string common = " --markers " + Markers().string() + " --blocking --quiet --out ";
  Outcome outcome = Run("run --dataset " + Sequence().string() + common + (dir_ / "run_seq").string());
  ASSERT_EQ(outcome.status, 0) << outcome.err;
  outcome = Run("run --dataset " + Bag().string() + " --image-topic /cam/image_raw" + common +
                (dir_ / "run_bag").string());
  ASSERT_EQ(outcome.status, 0) << outcome.err;
  const Trajectory sequence = ReadTumTrajectory(dir_ / "run_seq" / "trajectory.tum");
  const Trajectory bag = ReadTumTrajectory(dir_ / "run_bag" / "trajectory.tum");
  ASSERT_GT(sequence.size(), ReadFrames(Sequence()).size() / 2);
  ASSERT_EQ(bag.size(), sequence.size());
  double worst_m = 0.0;
  for (std::size_t i = 0; i < bag.size(); ++i) {
    EXPECT_EQ(bag.timestamps[i], sequence.timestamps[i]) << i;
    worst_m = std::max(worst_m, (bag.poses[i].translation - sequence.poses[i].translation).norm());
  }
  EXPECT_LE(worst_m, 0.001);  // measured: identical
  EXPECT_NE(ReadText(dir_ / "run_bag" / "stats.json").find("\"rosbag\""), std::string::npos);
}

TEST_F(BagEndToEndTest, BadBagsAreOneLineAndExitTwoWithNothingWritten) {
  const fs::path no_info = dir_ / "no_info.bag";
  WriteBag(no_info, /*with_camera_info=*/false);
  const fs::path corrupt = dir_ / "corrupt.bag";
  fs::copy_file(Bag(), corrupt, fs::copy_options::overwrite_existing);
  fs::resize_file(corrupt, fs::file_size(corrupt) / 3);
  const fs::path out = dir_ / "bad_out";
  const struct {
    std::string arguments;
    std::string expected;  // in the error line
  } cases[] = {
      {"--dataset " + Bag().string() + " --image-topic /camera/image", "/cam/image_raw"},
      {"--dataset " + Bag().string(), "--image-topic"},
      {"--dataset " + no_info.string() + " --image-topic /cam/image_raw", "--camera"},
      {"--dataset " + corrupt.string() + " --image-topic /cam/image_raw", corrupt.string()},
      {"--dataset " + Sequence().string() + " --image-topic /cam/image_raw", "only for a ROS bag"},
  };
  for (const auto& bad : cases) {
    const Outcome outcome = Run("run " + bad.arguments + " --quiet --out " + out.string());
    EXPECT_EQ(outcome.status, 2) << bad.arguments << "\n" << outcome.err;
    EXPECT_EQ(std::count(outcome.err.begin(), outcome.err.end(), '\n'), 1) << outcome.err;
    EXPECT_NE(outcome.err.find(bad.expected), std::string::npos) << outcome.err;
    EXPECT_FALSE(fs::exists(out)) << bad.arguments;
  }
  // A missing camera_info is fine with a calibration file.
  const Outcome outcome = Run("run --dataset " + no_info.string() + " --image-topic /cam/image_raw "
                              "--camera " + (dir_ / "camera.yaml").string() +
                              " --no-markers --blocking --quiet --out " + out.string());
  EXPECT_EQ(outcome.status, 0) << outcome.err;
}

// Receives the node's tf poses of "camera" and its per-frame status stamps.
class NodeListener {
 public:
  explicit NodeListener(ros::NodeHandle& node)
      : tf_(node.subscribe("/tf", 1000, &NodeListener::OnTf, this)),
        status_(node.subscribe("/arucoslam/status", 1000, &NodeListener::OnStatus, this)) {}

  bool Connected() const { return tf_.getNumPublishers() > 0 && status_.getNumPublishers() > 0; }
  // Waits until the status of the frame stamped `stamp` arrived.
  bool WaitForStatus(const ros::Time& stamp, std::chrono::seconds timeout) {
    std::unique_lock lock(mutex_);
    return arrived_.wait_for(lock, timeout, [&] { return statuses_.count(stamp) > 0; });
  }
  Trajectory Poses() {
    std::lock_guard lock(mutex_);
    Trajectory trajectory;
    for (const auto& [stamp, pose] : poses_) trajectory.Add(1e-9 * static_cast<double>(stamp.toNSec()), pose);
    return trajectory;
  }
  std::size_t NumStatuses() {
    std::lock_guard lock(mutex_);
    return statuses_.size();
  }

 private:
  void OnTf(const tf2_msgs::TFMessageConstPtr& message) {
    std::lock_guard lock(mutex_);
    for (const geometry_msgs::TransformStamped& transform : message->transforms) {
      if (transform.header.frame_id != "world" || transform.child_frame_id != "camera") continue;
      const auto& t = transform.transform;
      poses_[transform.header.stamp] =
          Rigid3(Eigen::Quaterniond(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z),
                 Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z));
    }
  }
  void OnStatus(const diagnostic_msgs::DiagnosticArrayConstPtr& message) {
    {
      std::lock_guard lock(mutex_);
      statuses_.insert(message->header.stamp);
    }
    arrived_.notify_all();
  }

  ros::Subscriber tf_;
  ros::Subscriber status_;
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::map<ros::Time, Rigid3> poses_;
  std::set<ros::Time> statuses_;
};

void BagEndToEndTest::PlayBagIntoNode(pid_t node_pid, const fs::path& log,
                                      NodeOutcome* outcome) {
  ASSERT_GT(node_pid, 0);
  ros::NodeHandle node;
  ros::AsyncSpinner spinner(1);
  spinner.start();
  NodeListener listener(node);
  ros::Publisher images = node.advertise<sensor_msgs::Image>("/cam/image_raw", 100);
  ros::Publisher infos = node.advertise<sensor_msgs::CameraInfo>("/cam/camera_info", 100);
  const auto connect_deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while ((images.getNumSubscribers() == 0 || infos.getNumSubscribers() == 0 ||
          !listener.Connected()) &&
         std::chrono::steady_clock::now() < connect_deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_GT(images.getNumSubscribers(), 0u) << ReadText(log);
  ASSERT_TRUE(listener.Connected()) << ReadText(log);
  // Each image after the camera_info of its stamp; the first image waits until the first
  // camera_info has had time to arrive (the node drops images that come before it).
  rosbag::Bag bag(Bag().string(), rosbag::bagmode::Read);
  rosbag::View view(bag);
  std::map<ros::Time, sensor_msgs::CameraInfo::ConstPtr> info_at;
  std::vector<sensor_msgs::Image::ConstPtr> bag_images;
  for (const rosbag::MessageInstance& message : view) {
    if (const auto info = message.instantiate<sensor_msgs::CameraInfo>()) {
      info_at[info->header.stamp] = info;
    } else if (const auto image = message.instantiate<sensor_msgs::Image>()) {
      bag_images.push_back(image);
    }
  }
  for (const sensor_msgs::Image::ConstPtr& image : bag_images) {
    if (const auto info = info_at.find(image->header.stamp); info != info_at.end()) {
      infos.publish(*info->second);
      if (outcome->num_images == 0) std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
    images.publish(*image);
    ++outcome->num_images;
    ASSERT_TRUE(listener.WaitForStatus(image->header.stamp, std::chrono::seconds(30)))
        << "no status for image " << outcome->num_images << "\n" << ReadText(log);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the last tf messages
  outcome->num_statuses = listener.NumStatuses();
  outcome->poses = listener.Poses();
  spinner.stop();
  EXPECT_EQ(EndProcess(node_pid, std::chrono::seconds(30)), 0) << ReadText(log);
}

// The node publishes a frame's pose once it is in the marker world: from the first marker
// fix or world alignment on. The run's trajectory also holds the frames before (given
// world poses at the end): it is compared on the node's frames. Its online.tum holds what
// each frame gave when it was tracked, as the node publishes it.
void BagEndToEndTest::CompareWithRun(const NodeOutcome& node) {
  const fs::path out = dir_ / "run_threaded";
  if (!fs::exists(out / "trajectory.tum")) {
    const Outcome outcome = Run("run --dataset " + Bag().string() +
                                " --image-topic /cam/image_raw --markers " +
                                Markers().string() + " --quiet --out " + out.string());
    ASSERT_EQ(outcome.status, 0) << outcome.err;
  }
  const Trajectory truth = Truth();
  const Trajectory run = ReadTumTrajectory(out / "trajectory.tum");
  Trajectory run_on_node_frames;
  for (std::size_t i = 0; i < run.size(); ++i) {
    if (!node.poses.empty() && run.timestamps[i] >= node.poses.timestamps.front() - 1e-6) {
      run_on_node_frames.Add(run.timestamps[i], run.poses[i]);
    }
  }
  const Trajectory run_online = ReadTumTrajectory(out / "online.tum");
  const auto [run_ate, run_matched] = WorldAte(truth, run);
  const auto [run_same_ate, run_same_matched] = WorldAte(truth, run_on_node_frames);
  const auto [online_ate, online_matched] = WorldAte(truth, run_online);
  const auto [node_ate, node_matched] = WorldAte(truth, node.poses);
  std::printf("world ATE: node %.4f m over %zu tf poses; threaded run %.4f m over %zu poses, "
              "%.4f m over its %zu poses from the node's first on, online %.4f m over %zu "
              "(%zu frames)\n",
              node_ate, node_matched, run_ate, run_matched, run_same_ate, run_same_matched,
              online_ate, online_matched, node.num_images);
  EXPECT_EQ(node.num_statuses, node.num_images);
  EXPECT_GE(node_matched, run_same_matched * 9 / 10);
  EXPECT_GE(node_matched, node.num_images / 3);
  EXPECT_GE(node_matched, online_matched * 9 / 10);
  // A tf pose is the estimate when its frame was tracked; the run's trajectory adds the
  // end-of-run adjustments (whole-map marker BA, frame refinement): within 1 cm of it.
  EXPECT_NEAR(node_ate, run_same_ate, 0.01);
  EXPECT_NEAR(node_ate, online_ate, 0.01);
}

TEST_F(BagEndToEndTest, NodePublishesTfPosesInTheMarkerWorld) {
  if (std::string(ARUCOSLAM_ROSMASTER).empty()) GTEST_SKIP() << "rosmaster not installed";
  ASSERT_TRUE(RosSession::Start(dir_)) << ReadText(dir_ / "rosmaster.log");
  const fs::path log = dir_ / "node.log";
  const pid_t node_pid = StartProcess(
      {ARUCOSLAM_ROS_NODE, "__name:=arucoslam", "image:=/cam/image_raw",
       "camera_info:=/cam/camera_info", "_markers:=" + Markers().string(), "_queue_size:=100"},
      log);
  NodeOutcome node;
  PlayBagIntoNode(node_pid, log, &node);
  if (HasFatalFailure()) return;
  CompareWithRun(node);
}

// The launch file users start, from the package folder the build makes (build/ros_package):
// roslaunch finds the package and its node, hands it the arguments as parameters and
// remappings, and the node gives the same poses as when started by hand.
TEST_F(BagEndToEndTest, TheLaunchFileStartsTheNode) {
  if (std::string(ARUCOSLAM_ROSLAUNCH).empty()) GTEST_SKIP() << "roslaunch not installed";
  ASSERT_TRUE(RosSession::Start(dir_)) << ReadText(dir_ / "rosmaster.log");
  ASSERT_TRUE(fs::exists(fs::path(ARUCOSLAM_ROS_PACKAGE_PATH) / "arucoslam" / "package.xml"));
  setenv("ROS_PACKAGE_PATH", ARUCOSLAM_ROS_PACKAGE_PATH, 1);
  const fs::path log = dir_ / "roslaunch.log";
  const pid_t launch_pid = StartProcess(
      {ARUCOSLAM_ROSLAUNCH, "arucoslam", "arucoslam.launch", "image:=/cam/image_raw",
       "camera_info:=/cam/camera_info", "markers:=" + Markers().string(), "queue_size:=100"},
      log);
  NodeOutcome node;
  PlayBagIntoNode(launch_pid, log, &node);
  if (HasFatalFailure()) return;
  EXPECT_NE(ReadText(log).find("arucoslam (arucoslam/arucoslam_ros)"), std::string::npos)
      << ReadText(log);
  CompareWithRun(node);
}

}  // namespace
}  // namespace arucoslam
