// Dataset: the image sequences stored as files (EuRoC layout, TUM RGB-D folder, KITTI odometry
// folder, plain image folder): the frames in time order, the camera and optional ground truth.
// io/frame_source.h streams these and videos and live cameras through one interface.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/io/trajectory_io.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

enum class DatasetLayout {
  kAuto,         // EuRoC when mav0/cam0/data.csv exists, TUM when rgb.txt exists, KITTI when
                 // times.txt or calib.txt exists, else images
  kEuroc,        // SEQ/mav0/cam0/{data.csv,data/,sensor.yaml}, optional ground truth
  kTumRgbd,      // SEQ/rgb.txt (+ groundtruth.txt); camera from DatasetOptions::camera_path
  kImageFolder,  // SEQ/*.{png,jpg,jpeg,pgm,bmp,tif,tiff} sorted by name; timestamps from a rate
  kKitti,        // KITTI odometry: SEQ/image_0/NNNNNN.png (else image_2/), SEQ/times.txt,
                 // SEQ/calib.txt (P0, or P2 for image_2); ground truth from
                 // SEQ/../../poses/<SEQ name>.txt or DatasetOptions::ground_truth_path
};

std::string DatasetLayoutName(DatasetLayout layout);

struct DatasetOptions {
  DatasetLayout layout = DatasetLayout::kAuto;
  // Calibration file (any format of io/calibration.h). Required for TUM and image folders;
  // for EuRoC it replaces mav0/cam0/sensor.yaml when given.
  std::filesystem::path camera_path;
  // Image folder: frame rate in Hz that gives the timestamps (index / rate). 0: the camera
  // file's rate_hz, or 20 Hz when that is unknown too.
  double rate_hz = 0.0;
  // KITTI: a poses file (12 numbers per line, world_from_cam0, one line per times.txt line)
  // to use as ground truth instead of SEQ/../../poses/<SEQ name>.txt. Empty: that one if present.
  std::filesystem::path ground_truth_path;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("rate_hz", rate_hz, 0.0);
    return check.ok();
  }
};

struct DatasetFrame {
  std::size_t index = 0;          // 0-based position in the sequence
  std::int64_t timestamp_ns = 0;  // exact as the index file gives it (image folder: rounded)
  double timestamp_s = 0.0;
  std::filesystem::path image_path;
};

class Dataset {
 public:
  // Reads the sequence's index files and the camera, and checks the first image (readable,
  // size equal to the calibration's). Throws InputError naming the file at fault: missing
  // folder or index file, malformed line (file and line number), timestamps not increasing,
  // listed image missing, unreadable image, wrong resolution, empty sequence, missing camera.
  static Dataset Open(const std::filesystem::path& root, const DatasetOptions& options = {});

  DatasetLayout layout() const { return layout_; }
  const std::filesystem::path& root() const { return root_; }
  const CameraModel& camera() const { return camera_; }
  // The camera's mounting on the body whose poses the ground-truth file gives (EuRoC T_BS).
  const Rigid3& body_from_cam() const { return body_from_cam_; }

  std::size_t size() const { return frames_.size(); }
  const DatasetFrame& frame(std::size_t index) const { return frames_.at(index); }
  const std::vector<DatasetFrame>& frames() const { return frames_; }
  // Frame `index` as an 8-bit grey image. Throws InputError (the image's path) when it
  // cannot be read or its size differs from the camera's.
  cv::Mat LoadImage(std::size_t index) const;

  // Ground truth as world_from_cam (EuRoC body poses are multiplied by body_from_cam);
  // empty when the sequence has none.
  const Trajectory& ground_truth() const { return ground_truth_; }
  bool has_ground_truth() const { return !ground_truth_.empty(); }
  // SEQ/markers.json when present.
  std::optional<std::filesystem::path> markers_path() const;

 private:
  DatasetLayout layout_ = DatasetLayout::kAuto;
  std::filesystem::path root_;
  CameraModel camera_;
  Rigid3 body_from_cam_;
  std::vector<DatasetFrame> frames_;
  Trajectory ground_truth_;

  static Dataset OpenEuroc(const std::filesystem::path& root, const DatasetOptions& options);
  static Dataset OpenTum(const std::filesystem::path& root, const DatasetOptions& options);
  static Dataset OpenImageFolder(const std::filesystem::path& root, const DatasetOptions& options);
  static Dataset OpenKitti(const std::filesystem::path& root, const DatasetOptions& options);
};

// Loads an image as 8-bit grey and checks its size against `camera` (both throw InputError).
cv::Mat LoadGreyImage(const std::filesystem::path& path, const CameraModel& camera);

}  // namespace arucoslam
