// Acceptance checks of the real inputs: a rational-8 camera used as calibrated (no undistortion
// first), a KITTI odometry folder run directly, and a video file giving the trajectory of the
// image sequence it was made from.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "arucoslam/exe/command_test_util.h"
#include "arucoslam/geometry/umeyama.h"
#include "arucoslam/io/calibration.h"
#include "arucoslam/io/dataset_reader.h"
#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/io/path_json.h"
#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/markers/camera_locator.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;
using testing_util::RunArucoslamSplit;
using testing_util::SplitCommandResult;

const fs::path kData = ARUCOSLAM_TEST_DATA_DIR;
const fs::path kLifecam = kData / "photonvision_charuco_lifecam";

class RealInputsTest : public ::testing::Test {
 protected:
  SplitCommandResult Run(const std::string& arguments) const {
    return RunArucoslamSplit(arguments, dir_);
  }

  ScratchFolder scratch_{"real_inputs_test"};
  const fs::path& dir_ = scratch_.path();
};

// The ChArUco board's 32 markers from the data set's layout file (board frame: x right, y down,
// z into the board; a marker's frame has y up and z out of the face, so it is the board frame
// turned half a turn about x).
MarkerMap BoardMarkers() {
  const nlohmann::json layout =
      nlohmann::json::parse(ReadTextFile(kLifecam / "marker_layout_board.json"));
  MarkerMap map;
  map.dictionary = "DICT_4X4_1000";
  for (const nlohmann::json& entry : layout["markers"]) {
    MarkerInfo marker;
    marker.id = entry["id"];
    marker.size = entry["size_m"];
    const std::vector<double> centre = entry["center_m"];
    marker.world_from_marker =
        Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX())),
               Eigen::Vector3d(centre[0], centre[1], centre[2]));
    map.markers[marker.id] = marker;
  }
  return map;
}

std::optional<Rigid3> Locate(const cv::Mat& image, const MarkerMap& map,
                             const CameraModel& camera) {
  DetectorOptions options;
  options.dictionary = map.dictionary;
  const CameraLocation location = LocateCamera(MarkerDetector(options).Detect(image), map, camera);
  if (!location.found) return std::nullopt;
  return location.world_from_cam;
}

// (a) The LifeCam's own rational-8 calibration on the raw images gives the same marker poses
// as its cv::undistort'ed images with a distortion-free camera.
TEST_F(RealInputsTest, Rational8CameraLocatesAsTheUndistortedImages) {
  if (!fs::exists(kLifecam)) GTEST_SKIP() << "test data missing: " << kLifecam;
  const CameraModel camera = ReadCameraModel(kLifecam / "camera_opencv.yaml");
  ASSERT_EQ(camera.model, DistortionModel::kRational);
  CameraModel pinhole = camera;
  pinhole.model = DistortionModel::kNone;
  pinhole.distortion = {};
  const cv::Matx33d k(camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0);
  const MarkerMap board = BoardMarkers();
  ASSERT_EQ(board.markers.size(), 32u);
  double worst_m = 0.0, worst_ignored_m = 0.0;
  for (const int index : {0, 30, 60, 90, 120}) {
    const cv::Mat raw =
        cv::imread((kLifecam / "original" / ("img" + std::to_string(index) + ".png")).string(),
                   cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(raw.empty()) << index;
    cv::Mat undistorted;
    cv::undistort(raw, undistorted, k, camera.DistortionCoefficients());
    const std::optional<Rigid3> direct = Locate(raw, board, camera);
    const std::optional<Rigid3> through_undistort = Locate(undistorted, board, pinhole);
    const std::optional<Rigid3> distortion_ignored = Locate(raw, board, pinhole);
    ASSERT_TRUE(direct && through_undistort && distortion_ignored) << "image " << index;
    const double difference_m = (direct->translation - through_undistort->translation).norm();
    worst_m = std::max(worst_m, difference_m);
    worst_ignored_m = std::max(
        worst_ignored_m, (distortion_ignored->translation - through_undistort->translation).norm());
    EXPECT_LT(direct->rotation.angularDistance(through_undistort->rotation), 0.002)
        << "image " << index;
  }
  RecordProperty("worst_position_difference_mm", std::to_string(1e3 * worst_m));
  EXPECT_LT(worst_m, 1e-3);
  // The distortion matters: ignoring it moves the camera by more than the agreement above.
  EXPECT_GT(worst_ignored_m, 2.0 * worst_m);
  std::printf(
      "rational-8 vs undistorted images: worst camera position difference %.3f mm "
      "(distortion ignored: %.3f mm)\n",
      1e3 * worst_m, 1e3 * worst_ignored_m);
}

// Camera positions of an estimate against the data set's per-frame PnP poses (frame i of the
// reference has timestamp 1e9 + i s).
struct PnpComparison {
  double rms_m = 0.0;   // over the frames the reference holds
  int num_outside = 0;  // frames of the estimate the reference does not hold
};

PnpComparison CompareWithPnpReference(const Trajectory& estimate, const Trajectory& reference) {
  PnpComparison comparison;
  double sum = 0.0;
  int num_inside = 0;
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    const long long r = std::llround(estimate.timestamps[i] - 1e9);
    if (r < 0 || static_cast<std::size_t>(r) >= reference.size()) {
      ++comparison.num_outside;
      continue;
    }
    const Eigen::Vector3d& truth = reference.poses[static_cast<std::size_t>(r)].translation;
    sum += (estimate.poses[i].translation - truth).squaredNorm();
    ++num_inside;
  }
  comparison.rms_m = std::sqrt(sum / std::max(1, num_inside));
  return comparison;
}

// (a) `run` takes the OpenCV FileStorage calibration as it is and tracks with the board's
// markers; its marker-located poses agree with the data set's PnP reference.
TEST_F(RealInputsTest, RunUsesTheRational8CalibrationFile) {
  if (!fs::exists(kLifecam)) GTEST_SKIP() << "test data missing: " << kLifecam;
  WriteMarkerMapJson(BoardMarkers(), dir_ / "board.json");
  const SplitCommandResult result = Run(
      "run --dataset " + (kLifecam / "euroc").string() + " --camera " +
      (kLifecam / "camera_opencv.yaml").string() + " --markers " + (dir_ / "board.json").string() +
      " --max-frames 8 --blocking --quiet --out " + (dir_ / "out").string());
  ASSERT_EQ(result.status, 0) << result.err;
  const std::string stats = ReadTextFile(dir_ / "out" / "stats.json");
  EXPECT_NE(stats.find("\"total\": 8"), std::string::npos) << stats;
  const Trajectory estimate = ReadTumTrajectory(dir_ / "out" / "trajectory.tum");
  const Trajectory reference = ReadTumTrajectory(kLifecam / "reference_pnp_world_from_cam_tum.txt");
  ASSERT_GE(estimate.size(), 6u) << stats;
  const PnpComparison pnp = CompareWithPnpReference(estimate, reference);
  EXPECT_EQ(pnp.num_outside, 0);
  const double rms_m = pnp.rms_m;
  std::printf("lifecam run: %zu poses, %.2f mm RMS from the PnP reference\n", estimate.size(),
              1e3 * rms_m);
  EXPECT_LT(rms_m, 0.01);
}

// Marker-first mapping on the real board: `run` maps the board's markers from frames posed by
// markers alone (no keypoint map settles here: a hand-held planar scene), poses every frame,
// and the mapped corners match the printed layout.
struct BoardMapping {
  MarkerMap mapped;
  double corner_rms_m = 0.0;  // mapped corners against the printed layout, after a rigid fit
  Trajectory trajectory;
};

BoardMapping MapBoard(const std::string& markers_arguments, const fs::path& out) {
  const SplitCommandResult result = RunArucoslamSplit(
      "run --dataset " + (kLifecam / "euroc").string() + " --camera " +
      (kLifecam / "camera_opencv.yaml").string() + " " + markers_arguments +
      " --blocking --quiet --out " + out.string(), out.parent_path());
  EXPECT_EQ(result.status, 0) << result.err;
  BoardMapping mapping;
  if (result.status != 0) return mapping;
  mapping.mapped = ReadMarkerMapJson(out / "markers.json");
  mapping.trajectory = ReadTumTrajectory(out / "trajectory.tum");
  const MarkerMap board = BoardMarkers();
  std::vector<Eigen::Vector3d> estimated, printed;
  for (const auto& [id, marker] : mapping.mapped.markers) {
    EXPECT_EQ(board.markers.count(id), 1u) << "marker " << id << " is not on the board";
    if (board.markers.count(id) == 0) continue;
    const auto corners = marker.CornersInWorld();
    const auto truth = board.markers.at(id).CornersInWorld();
    estimated.insert(estimated.end(), corners.begin(), corners.end());
    printed.insert(printed.end(), truth.begin(), truth.end());
  }
  const std::optional<Sim3> rigid = UmeyamaAlignment(estimated, printed, AlignmentKind::kRigid);
  EXPECT_TRUE(rigid);
  if (!rigid) return mapping;
  double sum = 0.0;
  for (std::size_t i = 0; i < estimated.size(); ++i) {
    sum += (*rigid * estimated[i] - printed[i]).squaredNorm();
  }
  mapping.corner_rms_m = std::sqrt(sum / estimated.size());
  return mapping;
}

TEST_F(RealInputsTest, MapsTheBoardFromOneKnownMarker) {
  if (!fs::exists(kLifecam)) GTEST_SKIP() << "test data missing: " << kLifecam;
  const MarkerMap board = BoardMarkers();
  MarkerMap one = board;
  one.markers = {{13, board.markers.at(13)}};
  WriteMarkerMapJson(one, dir_ / "one.json");
  const BoardMapping mapping = MapBoard("--markers " + (dir_ / "one.json").string(), dir_ / "out");
  const Trajectory& estimate = mapping.trajectory;
  const Trajectory reference = ReadTumTrajectory(kLifecam / "reference_pnp_world_from_cam_tum.txt");
  const PnpComparison pnp = CompareWithPnpReference(estimate, reference);
  EXPECT_EQ(pnp.num_outside, 0);
  const double pose_rms_m = pnp.rms_m;
  std::printf("lifecam, marker 13 known: %zu of %zu frames posed, %zu markers, corners %.2f mm "
              "RMS from the layout (rigid), poses %.2f mm RMS from the PnP reference\n",
              estimate.size(), reference.size(), mapping.mapped.markers.size(),
              1e3 * mapping.corner_rms_m, 1e3 * pose_rms_m);
  EXPECT_EQ(mapping.mapped.markers.size(), 32u);
  EXPECT_GE(estimate.size(), static_cast<std::size_t>(std::ceil(0.99 * reference.size())));
  EXPECT_LT(mapping.corner_rms_m, 0.002);
  EXPECT_LT(pose_rms_m, 0.005);
}

// With the whole board known, every frame is located from the markers it sees and its pose
// agrees with the data set's per-frame PnP on the ChArUco corners.
TEST_F(RealInputsTest, PosesWithTheWholeBoardKnownAgreeWithPerFramePnp) {
  if (!fs::exists(kLifecam)) GTEST_SKIP() << "test data missing: " << kLifecam;
  WriteMarkerMapJson(BoardMarkers(), dir_ / "board.json");
  const BoardMapping mapping =
      MapBoard("--markers " + (dir_ / "board.json").string(), dir_ / "out");
  const Trajectory reference = ReadTumTrajectory(kLifecam / "reference_pnp_world_from_cam_tum.txt");
  const PnpComparison pnp = CompareWithPnpReference(mapping.trajectory, reference);
  EXPECT_EQ(pnp.num_outside, 0);
  const double pose_rms_m = pnp.rms_m;
  std::printf("lifecam, whole board known: %zu of %zu frames posed, poses %.2f mm RMS from the "
              "PnP reference\n",
              mapping.trajectory.size(), reference.size(), 1e3 * pose_rms_m);
  EXPECT_EQ(mapping.trajectory.size(), reference.size());
  EXPECT_LT(pose_rms_m, 0.002);
}

// With no marker known, the first frame's largest marker becomes the world's origin and the
// board is mapped around it.
TEST_F(RealInputsTest, MapsTheBoardWithNoMarkerKnown) {
  if (!fs::exists(kLifecam)) GTEST_SKIP() << "test data missing: " << kLifecam;
  MarkerMap none = BoardMarkers();
  none.markers.clear();
  WriteMarkerMapJson(none, dir_ / "none.json");
  const BoardMapping mapping = MapBoard(
      "--markers " + (dir_ / "none.json").string() + " --marker-size 0.01905", dir_ / "out");
  std::printf("lifecam, no marker known: %zu frames posed, %zu markers, corners %.2f mm RMS "
              "from the layout (rigid)\n",
              mapping.trajectory.size(), mapping.mapped.markers.size(),
              1e3 * mapping.corner_rms_m);
  EXPECT_EQ(mapping.mapped.markers.size(), 32u);
  int origins = 0;
  for (const auto& [id, marker] : mapping.mapped.markers) {
    if (!marker.fixed) continue;
    ++origins;
    EXPECT_LT(marker.world_from_marker.translation.norm(), 1e-12);
  }
  EXPECT_EQ(origins, 1);
  EXPECT_GE(mapping.trajectory.size(), 122u);  // 99% of 123
  EXPECT_LT(mapping.corner_rms_m, 0.002);
}

// (b) The KITTI odometry folder as published (image_0/, calib.txt, times.txt) runs directly.
TEST_F(RealInputsTest, KittiFolderRunsDirectly) {
  const fs::path kitti = kData / "kitti07_first160" / "original";
  if (!fs::exists(kitti)) GTEST_SKIP() << "test data missing: " << kitti;
  const SplitCommandResult result =
      Run("run --dataset " + kitti.string() + " --max-frames 40 --blocking --quiet --out " +
          (dir_ / "out").string());
  ASSERT_EQ(result.status, 0) << result.err;
  const std::string stats = ReadTextFile(dir_ / "out" / "stats.json");
  EXPECT_NE(stats.find("\"layout\": \"kitti\""), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"total\": 40"), std::string::npos) << stats;
  const Trajectory estimate = ReadTumTrajectory(dir_ / "out" / "trajectory.tum");
  EXPECT_GE(estimate.size(), 20u) << result.out;
  // KITTI times.txt timestamps: frame 39 at 4.05 s.
  ASSERT_FALSE(estimate.empty());
  EXPECT_LT(estimate.timestamps.back(), 4.1);
}

// A short simulated sequence (one aisle of the factory, 4 m at 15 Hz, 320x240, markers at the
// docks) and a lossless video of its images (FFV1 in Matroska), made once for the tests below.
class SimulatedVideoTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("arucoslam_video_input_test_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    SplitCommandResult result =
        Run("world factory --seed 3 --aisles 1 --aisle-length 8 --wall-markers 0 "
            "--markers-per-dock 4 "
            "--marker-size 0.3 --out " +
            (dir_ / "world").string());
    ASSERT_EQ(result.status, 0) << result.err;
    const CameraModel camera = PinholeCamera(320, 240, 230.0);
    WriteEuRoCSensorYaml(camera, dir_ / "camera.yaml");
    PathSpec spec = ReadPathJson(dir_ / "world" / "path.json");
    spec.options.camera_rate_hz = 15.0;
    spec.waypoints = {{6.0, 4.6, 0.0}, {10.0, 4.6, 0.0}};
    WritePathJson(dir_ / "path.json", spec);
    result = Run("simulate --world " + (dir_ / "world" / "world.sdf").string() + " --path " +
                 (dir_ / "path.json").string() + " --camera " + (dir_ / "camera.yaml").string() +
                 " --msaa 1 --quiet --out " + (dir_ / "seq").string());
    ASSERT_EQ(result.status, 0) << result.err;
    const Dataset sequence = Dataset::Open(dir_ / "seq");
    cv::VideoWriter writer((dir_ / "seq.mkv").string(), cv::CAP_FFMPEG,
                           cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 15.0,
                           cv::Size(camera.width, camera.height), false);
    ASSERT_TRUE(writer.isOpened());
    for (std::size_t i = 0; i < sequence.size(); ++i) writer.write(sequence.LoadImage(i));
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static SplitCommandResult Run(const std::string& arguments) {
    return RunArucoslamSplit(arguments, dir_);
  }
  static std::string MarkerArgs() {
    return " --markers " + (dir_ / "seq" / "markers.json").string() + " --blocking --quiet ";
  }

  static fs::path dir_;
};

fs::path SimulatedVideoTest::dir_;

// (c) The video gives the trajectory of the image sequence, in the marker world frame.
TEST_F(SimulatedVideoTest, VideoFileGivesTheImageSequencesTrajectory) {
  SplitCommandResult result = Run("run --dataset " + (dir_ / "seq").string() + MarkerArgs() +
                                  "--out " + (dir_ / "images").string());
  ASSERT_EQ(result.status, 0) << result.err;
  result =
      Run("run --dataset " + (dir_ / "seq.mkv").string() + " --camera " +
          (dir_ / "camera.yaml").string() + MarkerArgs() + "--out " + (dir_ / "video").string());
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_NE(ReadTextFile(dir_ / "video" / "stats.json").find("\"layout\": \"video\""),
            std::string::npos);

  const Dataset sequence = Dataset::Open(dir_ / "seq");
  const Trajectory from_images = ReadTumTrajectory(dir_ / "images" / "trajectory.tum");
  const Trajectory from_video = ReadTumTrajectory(dir_ / "video" / "trajectory.tum");
  ASSERT_GE(from_images.size(), 0.9 * sequence.size());
  ASSERT_GE(from_video.size(), 0.9 * sequence.size());
  // The video's clock starts at 0 with the first frame (Matroska: whole milliseconds); the
  // sequence's at its first stamp.
  const double start_s = sequence.frame(0).timestamp_s;
  std::map<double, Eigen::Vector3d> image_positions;
  for (std::size_t i = 0; i < from_images.size(); ++i) {
    image_positions[from_images.timestamps[i] - start_s] = from_images.poses[i].translation;
  }
  double sum = 0.0;
  int matched = 0;
  for (std::size_t i = 0; i < from_video.size(); ++i) {
    const auto it = image_positions.lower_bound(from_video.timestamps[i] - 2e-3);
    if (it == image_positions.end() || it->first > from_video.timestamps[i] + 2e-3) continue;
    sum += (from_video.poses[i].translation - it->second).squaredNorm();
    ++matched;
  }
  ASSERT_GE(matched, static_cast<int>(0.9 * from_video.size()));
  const double rms_m = std::sqrt(sum / matched);
  std::printf("video vs images: %d poses matched, %.4f m RMS apart\n", matched, rms_m);
  EXPECT_LT(rms_m, 0.01);
}

// The video opened as a live camera (`--device`): frames arrive faster than the SLAM takes
// them, so some are dropped, and stats.json counts them.
TEST_F(SimulatedVideoTest, LiveSourceDropsFramesAndCountsThem) {
  const SplitCommandResult result =
      Run("run --device " + (dir_ / "seq.mkv").string() + " --camera " +
          (dir_ / "camera.yaml").string() + MarkerArgs() + "--out " + (dir_ / "live").string());
  ASSERT_EQ(result.status, 0) << result.err;
  const nlohmann::json stats = nlohmann::json::parse(ReadTextFile(dir_ / "live" / "stats.json"));
  EXPECT_EQ(stats["layout"], "camera");
  const int total = stats["frames"]["total"], dropped = stats["frames"]["dropped"];
  const std::size_t frames = Dataset::Open(dir_ / "seq").size();
  EXPECT_EQ(static_cast<std::size_t>(total + dropped), frames);
  EXPECT_GT(dropped, 0);
  EXPECT_NE(result.out.find("frames dropped"), std::string::npos) << result.out;
}

// Ctrl-C (SIGINT) ends a run early with exit status 0 and its outputs written.
TEST_F(RealInputsTest, InterruptStopsTheRunAndWritesItsOutputs) {
  const fs::path kitti = kData / "kitti07_first160" / "original";
  if (!fs::exists(kitti)) GTEST_SKIP() << "test data missing: " << kitti;
  // The whole clip takes about 7 s; the interrupt comes after 2 s.
  const std::string command = std::string(ARUCOSLAM_BINARY) + " run --quiet --blocking --dataset " +
                              kitti.string() + " --out " + (dir_ / "out").string() +
                              " > /dev/null 2>&1 & pid=$!; sleep 2; kill -INT $pid; wait $pid";
  const int raw = std::system(("sh -c '" + command + "'").c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  EXPECT_EQ(WEXITSTATUS(raw), 0);
  const nlohmann::json stats = nlohmann::json::parse(ReadTextFile(dir_ / "out" / "stats.json"));
  EXPECT_TRUE(stats["interrupted"].get<bool>());
  EXPECT_LT(stats["frames"]["total"].get<int>(), 160);
  EXPECT_TRUE(fs::is_regular_file(dir_ / "out" / "trajectory.tum"));
}

}  // namespace
}  // namespace arucoslam
