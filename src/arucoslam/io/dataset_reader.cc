#include "arucoslam/io/dataset_reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <sstream>

#include "arucoslam/io/calibration.h"
#include "arucoslam/io/image_file.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace fs = std::filesystem;
namespace {

std::string Trim(const std::string& text) {
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return {};
  const std::size_t last = text.find_last_not_of(" \t\r\n");
  return text.substr(first, last - first + 1);
}

bool ParseInt64(const std::string& text, std::int64_t* value) {
  if (text.empty()) return false;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), *value);
  return error == std::errc() && end == text.data() + text.size() && *value >= 0;
}

// "<seconds>[.<fraction>]" -> exact nanoseconds (fraction digits beyond 9 are dropped) and
// seconds as a double.
bool ParseSeconds(const std::string& text, std::int64_t* nanoseconds, double* seconds) {
  const std::size_t dot = text.find('.');
  const std::string whole = text.substr(0, dot);
  std::string fraction = dot == std::string::npos ? "" : text.substr(dot + 1);
  std::int64_t whole_value = 0;
  if (!ParseInt64(whole, &whole_value) || whole_value > 9'000'000'000LL) return false;
  if (!std::all_of(fraction.begin(), fraction.end(),
                   [](unsigned char c) { return std::isdigit(c) != 0; })) {
    return false;
  }
  fraction = (fraction + "000000000").substr(0, 9);
  std::int64_t fraction_value = 0;
  ParseInt64(fraction, &fraction_value);
  *nanoseconds = whole_value * 1'000'000'000LL + fraction_value;
  std::istringstream stream(text);
  stream >> *seconds;
  return true;
}

// Calls `fn(line_number, trimmed_line)` for every non-blank, non-comment line.
template <typename Fn>
void ForEachDataLine(const fs::path& path, Fn&& fn) {
  const std::string text = ReadTextFile(path);
  std::istringstream stream(text);
  std::string line;
  int line_number = 0;
  while (std::getline(stream, line)) {
    ++line_number;
    const std::string trimmed = Trim(line);
    if (trimmed.empty() || trimmed.front() == '#') continue;
    fn(line_number, trimmed);
  }
}

void RequireIncreasing(const std::vector<DatasetFrame>& frames, const fs::path& index_file,
                       int line_number) {
  if (frames.size() >= 2 && frames.back().timestamp_ns <= frames[frames.size() - 2].timestamp_ns) {
    throw InputError(index_file.string(),
                     fmt::format("line {}: timestamp {} is not after the previous one", line_number,
                                 frames.back().timestamp_ns));
  }
}

void RequireListedImage(const fs::path& image, const fs::path& index_file, int line_number) {
  if (!fs::is_regular_file(image)) {
    throw InputError(index_file.string(),
                     fmt::format("line {}: image {} not found", line_number, image.string()));
  }
}

bool IsImageFile(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  static const char* const kExtensions[] = {".png", ".jpg", ".jpeg", ".pgm",
                                            ".bmp", ".tif", ".tiff"};
  return std::any_of(std::begin(kExtensions), std::end(kExtensions),
                     [&](const char* known) { return extension == known; });
}

CameraCalibration RequireCamera(const DatasetOptions& options, const fs::path& root,
                                const std::string& layout) {
  if (options.camera_path.empty()) {
    throw InputError(
        root.string(),
        fmt::format("the {} layout needs a camera calibration file (--camera)", layout));
  }
  return ReadCameraCalibration(options.camera_path);
}

// KITTI times.txt: seconds in decimal or exponent notation ("1.038752e-01").
bool ParseKittiSeconds(const std::string& text, std::int64_t* nanoseconds, double* seconds) {
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), *seconds);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(*seconds) ||
      *seconds < 0.0) {
    return false;
  }
  *nanoseconds = std::llround(*seconds * 1e9);
  return true;
}

// A KITTI camera from calib.txt: "P<i>: " and the 12 numbers of the rectified 3x4 projection
// K [I | t]; t places the camera relative to camera 0 (P0 has t = 0). No distortion.
struct KittiCamera {
  CameraModel camera;
  Rigid3 cam0_from_cam;
};

KittiCamera ReadKittiCamera(const fs::path& path, int camera_index) {
  RequireFile(path, "KITTI calibration");
  const std::string key = fmt::format("P{}:", camera_index);
  std::optional<std::vector<double>> projection;
  ForEachDataLine(path, [&](int line_number, const std::string& line) {
    if (!line.starts_with(key)) return;
    std::istringstream fields(line.substr(key.size()));
    std::vector<double> values;
    std::string token;
    while (fields >> token) {
      double value = 0.0;
      const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
      if (error != std::errc() || end != token.data() + token.size() || !std::isfinite(value)) {
        throw InputError(path.string(), fmt::format("line {}: {} expected 12 numbers, found '{}'",
                                                    line_number, key, token));
      }
      values.push_back(value);
    }
    if (values.size() != 12) {
      throw InputError(path.string(), fmt::format("line {}: {} expected 12 numbers, found {}",
                                                  line_number, key, values.size()));
    }
    projection = values;
  });
  if (!projection) throw InputError(path.string(), fmt::format("{} missing", key));
  const std::vector<double>& p = *projection;
  KittiCamera kitti;
  CameraModel& camera = kitti.camera;
  camera.fx = p[0];
  camera.cx = p[2];
  camera.fy = p[5];
  camera.cy = p[6];
  if (!(camera.fx > 0.0) || !(camera.fy > 0.0) || p[1] != 0.0 || p[4] != 0.0 || p[8] != 0.0 ||
      p[9] != 0.0 || p[10] != 1.0) {
    throw InputError(path.string(),
                     fmt::format("{} expected a rectified projection [fx 0 cx tx; 0 fy cy ty; "
                                 "0 0 1 tz] with positive focal lengths",
                                 key));
  }
  // cam_from_cam0 translation = K^-1 (p3, p7, p11).
  const double tz = p[11];
  const Eigen::Vector3d cam_from_cam0((p[3] - camera.cx * tz) / camera.fx,
                                      (p[7] - camera.cy * tz) / camera.fy, tz);
  kitti.cam0_from_cam = Rigid3(Eigen::Quaterniond::Identity(), -cam_from_cam0);
  return kitti;
}

}  // namespace

std::string DatasetLayoutName(DatasetLayout layout) {
  switch (layout) {
    case DatasetLayout::kAuto:
      return "auto";
    case DatasetLayout::kEuroc:
      return "euroc";
    case DatasetLayout::kTumRgbd:
      return "tum";
    case DatasetLayout::kImageFolder:
      return "images";
    case DatasetLayout::kKitti:
      return "kitti";
  }
  return "unknown";
}

cv::Mat LoadGreyImage(const fs::path& path, const CameraModel& camera) {
  cv::Mat image = ReadImageFile(path, cv::IMREAD_GRAYSCALE);
  if (image.cols != camera.width || image.rows != camera.height) {
    throw InputError(path.string(),
                     fmt::format("image is {}x{} but the camera calibration says {}x{}", image.cols,
                                 image.rows, camera.width, camera.height));
  }
  return image;
}

Dataset Dataset::Open(const fs::path& root, const DatasetOptions& options) {
  if (!options.Check()) throw InputError("--rate", "the frame rate must not be negative");
  RequireDirectory(root, "sequence folder");
  DatasetLayout layout = options.layout;
  if (layout == DatasetLayout::kAuto) {
    if (fs::exists(root / "mav0" / "cam0" / "data.csv")) {
      layout = DatasetLayout::kEuroc;
    } else if (fs::exists(root / "rgb.txt")) {
      layout = DatasetLayout::kTumRgbd;
    } else if (fs::exists(root / "mav0")) {
      layout = DatasetLayout::kEuroc;  // EuRoC with something missing: say what
    } else if (fs::exists(root / "times.txt") || fs::exists(root / "calib.txt")) {
      layout = DatasetLayout::kKitti;
    } else {
      layout = DatasetLayout::kImageFolder;
    }
  }
  Dataset dataset = layout == DatasetLayout::kEuroc     ? OpenEuroc(root, options)
                    : layout == DatasetLayout::kTumRgbd ? OpenTum(root, options)
                    : layout == DatasetLayout::kKitti   ? OpenKitti(root, options)
                                                        : OpenImageFolder(root, options);
  dataset.layout_ = layout;
  dataset.root_ = root;
  if (dataset.frames_.empty() && options.layout == DatasetLayout::kAuto &&
      layout == DatasetLayout::kImageFolder) {
    throw InputError(root.string(),
                     "no frames: no known sequence layout (expected mav0/cam0/data.csv for "
                     "EuRoC, rgb.txt for TUM RGB-D, times.txt + calib.txt + image_0/ for KITTI, "
                     "or image files)");
  }
  if (dataset.frames_.empty()) {
    throw InputError(root.string(),
                     fmt::format("the {} sequence has no frames", DatasetLayoutName(layout)));
  }
  dataset.LoadImage(0);  // readable, and of the calibrated size
  return dataset;
}

Dataset Dataset::OpenEuroc(const fs::path& root, const DatasetOptions& options) {
  Dataset dataset;
  const fs::path cam_folder = root / "mav0" / "cam0";
  RequireDirectory(cam_folder, "EuRoC camera folder");
  const fs::path csv = cam_folder / "data.csv";
  RequireFile(csv, "EuRoC image list");
  const CameraCalibration calibration = ReadCameraCalibration(
      options.camera_path.empty() ? cam_folder / "sensor.yaml" : options.camera_path);
  dataset.camera_ = calibration.camera;
  dataset.body_from_cam_ = calibration.body_from_cam;
  ForEachDataLine(csv, [&](int line_number, const std::string& line) {
    const std::size_t comma = line.find(',');
    DatasetFrame frame;
    const std::string name = comma == std::string::npos ? "" : Trim(line.substr(comma + 1));
    if (comma == std::string::npos || name.empty() ||
        !ParseInt64(Trim(line.substr(0, comma)), &frame.timestamp_ns)) {
      throw InputError(csv.string(), fmt::format("line {}: expected '<timestamp [ns]>,<file "
                                                 "name>', found '{}'",
                                                 line_number, line));
    }
    frame.index = dataset.frames_.size();
    frame.timestamp_s = 1e-9 * static_cast<double>(frame.timestamp_ns);
    frame.image_path = cam_folder / "data" / name;
    RequireListedImage(frame.image_path, csv, line_number);
    dataset.frames_.push_back(frame);
    RequireIncreasing(dataset.frames_, csv, line_number);
  });
  const fs::path truth = root / "mav0" / "state_groundtruth_estimate0" / "data.csv";
  if (fs::exists(truth)) {
    const Trajectory world_from_body = ReadEurocTrajectory(truth);
    for (std::size_t i = 0; i < world_from_body.size(); ++i) {
      dataset.ground_truth_.Add(world_from_body.timestamps[i],
                                world_from_body.poses[i] * dataset.body_from_cam_);
    }
  }
  return dataset;
}

Dataset Dataset::OpenTum(const fs::path& root, const DatasetOptions& options) {
  Dataset dataset;
  const fs::path list = root / "rgb.txt";
  RequireFile(list, "TUM image list");
  const CameraCalibration calibration = RequireCamera(options, root, "TUM RGB-D");
  dataset.camera_ = calibration.camera;
  ForEachDataLine(list, [&](int line_number, const std::string& line) {
    std::istringstream fields(line);
    std::string stamp, name, extra;
    fields >> stamp >> name;
    DatasetFrame frame;
    if (name.empty() || (fields >> extra) ||
        !ParseSeconds(stamp, &frame.timestamp_ns, &frame.timestamp_s)) {
      throw InputError(list.string(), fmt::format("line {}: expected '<timestamp [s]> <file "
                                                  "name>', found '{}'",
                                                  line_number, line));
    }
    frame.index = dataset.frames_.size();
    frame.image_path = root / name;
    RequireListedImage(frame.image_path, list, line_number);
    dataset.frames_.push_back(frame);
    RequireIncreasing(dataset.frames_, list, line_number);
  });
  if (fs::exists(root / "groundtruth.txt")) {
    dataset.ground_truth_ = ReadTumTrajectory(root / "groundtruth.txt");
  }
  return dataset;
}

Dataset Dataset::OpenImageFolder(const fs::path& root, const DatasetOptions& options) {
  Dataset dataset;
  const CameraCalibration calibration = RequireCamera(options, root, "image-folder");
  dataset.camera_ = calibration.camera;
  double rate_hz = options.rate_hz;
  if (rate_hz <= 0.0) rate_hz = dataset.camera_.rate_hz > 0.0 ? dataset.camera_.rate_hz : 20.0;
  std::vector<fs::path> images;
  for (const fs::directory_entry& entry : fs::directory_iterator(root)) {
    if (entry.is_regular_file() && IsImageFile(entry.path())) images.push_back(entry.path());
  }
  std::sort(images.begin(), images.end());
  for (const fs::path& image : images) {
    DatasetFrame frame;
    frame.index = dataset.frames_.size();
    frame.timestamp_s = static_cast<double>(frame.index) / rate_hz;
    frame.timestamp_ns = std::llround(frame.timestamp_s * 1e9);
    frame.image_path = image;
    dataset.frames_.push_back(frame);
  }
  return dataset;
}

Dataset Dataset::OpenKitti(const fs::path& root, const DatasetOptions& options) {
  Dataset dataset;
  const int camera_index =
      fs::is_directory(root / "image_0") || !fs::is_directory(root / "image_2") ? 0 : 2;
  const fs::path image_folder = root / fmt::format("image_{}", camera_index);
  RequireDirectory(image_folder, "KITTI image folder (image_0 or image_2)");
  const fs::path times_path = root / "times.txt";
  RequireFile(times_path, "KITTI timestamps");
  std::vector<double> times;
  ForEachDataLine(times_path, [&](int line_number, const std::string& line) {
    std::int64_t nanoseconds = 0;
    double seconds = 0.0;
    if (!ParseKittiSeconds(line, &nanoseconds, &seconds)) {
      throw InputError(
          times_path.string(),
          fmt::format("line {}: expected a time in seconds, found '{}'", line_number, line));
    }
    times.push_back(seconds);
  });
  Rigid3 cam0_from_cam;
  if (options.camera_path.empty()) {
    const KittiCamera kitti = ReadKittiCamera(root / "calib.txt", camera_index);
    dataset.camera_ = kitti.camera;
    cam0_from_cam = kitti.cam0_from_cam;
  } else {
    dataset.camera_ = ReadCameraCalibration(options.camera_path).camera;
  }
  dataset.body_from_cam_ = cam0_from_cam;
  std::vector<fs::path> images;
  for (const fs::directory_entry& entry : fs::directory_iterator(image_folder)) {
    if (entry.is_regular_file() && IsImageFile(entry.path())) images.push_back(entry.path());
  }
  std::sort(images.begin(), images.end());
  for (const fs::path& image : images) {
    std::int64_t number = 0;
    if (!ParseInt64(image.stem().string(), &number)) {
      throw InputError(image.string(), "expected a KITTI frame number as the file name (000042)");
    }
    if (number >= static_cast<std::int64_t>(times.size())) {
      throw InputError(times_path.string(),
                       fmt::format("{} lines, but image {} needs line {}", times.size(),
                                   image.filename().string(), number + 1));
    }
    DatasetFrame frame;
    frame.index = dataset.frames_.size();
    frame.timestamp_s = times[number];
    frame.timestamp_ns = std::llround(frame.timestamp_s * 1e9);
    frame.image_path = image;
    dataset.frames_.push_back(frame);
    RequireIncreasing(dataset.frames_, times_path, static_cast<int>(number) + 1);
  }
  // calib.txt gives no image size: the calibrated camera takes the first image's.
  if (options.camera_path.empty() && !images.empty()) {
    const cv::Mat first = ReadImageFile(images.front(), cv::IMREAD_GRAYSCALE);
    dataset.camera_.width = first.cols;
    dataset.camera_.height = first.rows;
  }
  fs::path truth = options.ground_truth_path;
  if (truth.empty()) {
    const fs::path standard =
        root.parent_path().parent_path() / "poses" / (root.filename().string() + ".txt");
    if (fs::is_regular_file(standard)) truth = standard;
  }
  if (!truth.empty()) {
    const Trajectory world_from_cam0 = ReadKittiTrajectory(truth);
    if (world_from_cam0.size() > times.size()) {
      throw InputError(truth.string(),
                       fmt::format("{} poses but {} has {} lines", world_from_cam0.size(),
                                   times_path.string(), times.size()));
    }
    for (std::size_t i = 0; i < world_from_cam0.size(); ++i) {
      dataset.ground_truth_.Add(times[i], world_from_cam0.poses[i] * cam0_from_cam);
    }
  }
  return dataset;
}

cv::Mat Dataset::LoadImage(std::size_t index) const {
  return LoadGreyImage(frames_.at(index).image_path, camera_);
}

std::optional<fs::path> Dataset::markers_path() const {
  const fs::path path = root_ / "markers.json";
  if (fs::is_regular_file(path)) return path;
  return std::nullopt;
}

}  // namespace arucoslam
