#include "arucoslam/sim/dataset_writer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <future>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "arucoslam/io/calibration.h"
#include "arucoslam/sim/world_model.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/option_check.h"
#include "arucoslam/util/timing.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

constexpr const char* kGroundTruthHeader =
    "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
    "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], "
    "b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], "
    "b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n";

void WritePng(const fs::path& path, const cv::Mat& image, int compression) {
  const std::vector<int> parameters = {cv::IMWRITE_PNG_COMPRESSION, compression};
  if (!cv::imwrite(path.string(), image, parameters)) {
    throw InputError(path.string(), "cannot write the image");
  }
}

// Depth in metres (float) -> 16-bit millimetres; beyond 65.535 m or no hit: 0.
cv::Mat DepthMillimetres(const cv::Mat& depth_m) {
  cv::Mat millimetres(depth_m.size(), CV_16UC1);
  for (int v = 0; v < depth_m.rows; ++v) {
    const float* in = depth_m.ptr<float>(v);
    std::uint16_t* out = millimetres.ptr<std::uint16_t>(v);
    for (int u = 0; u < depth_m.cols; ++u) {
      const double mm = std::round(1000.0 * in[u]);
      out[u] = (mm > 0.0 && mm <= 65535.0) ? static_cast<std::uint16_t>(mm) : 0;
    }
  }
  return millimetres;
}

// Velocity by central differences (one-sided at the ends), metres per second.
Eigen::Vector3d Velocity(const std::vector<TimedPose>& poses, std::size_t i) {
  if (poses.size() < 2) return Eigen::Vector3d::Zero();
  const std::size_t a = i == 0 ? 0 : i - 1;
  const std::size_t b = std::min(i + 1, poses.size() - 1);
  const double dt = poses[b].time_s - poses[a].time_s;
  if (dt <= 0.0) return Eigen::Vector3d::Zero();
  return (poses[b].world_from_cam.translation - poses[a].world_from_cam.translation) / dt;
}

std::string GroundTruthCsv(const std::vector<TimedPose>& poses, std::int64_t start_time_ns) {
  std::string text = kGroundTruthHeader;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Rigid3& pose = poses[i].world_from_cam;
    Eigen::Quaterniond q = pose.rotation.normalized();
    if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // one sign for a rotation
    const Eigen::Vector3d& p = pose.translation;
    const Eigen::Vector3d v = Velocity(poses, i);
    text += fmt::format(
        "{},{:.9f},{:.9f},{:.9f},{:.12f},{:.12f},{:.12f},{:.12f},{:.6f},{:.6f},{:.6f},"
        "0,0,0,0,0,0\n",
        TimestampNs(poses[i].time_s, start_time_ns), p.x(), p.y(), p.z(), q.w(), q.x(), q.y(),
        q.z(), v.x(), v.y(), v.z());
  }
  return text;
}

// Copies world.sdf, markers.json beside it, and the files it uses below its folder.
void CopyWorld(const WorldModel& world, const fs::path& out_dir) {
  const fs::path world_dir = world.sdf_path.parent_path();
  fs::copy_file(world.sdf_path, out_dir / "world.sdf");
  std::error_code error;
  if (fs::is_regular_file(world_dir / "markers.json", error)) {
    fs::copy_file(world_dir / "markers.json", out_dir / "markers.json");
  }
  for (const fs::path& file : world.files) {
    const fs::path relative = file.lexically_relative(world_dir);
    if (relative.empty() || *relative.begin() == "..") continue;  // outside: stays absolute
    fs::create_directories((out_dir / relative).parent_path());
    fs::copy_file(file, out_dir / relative, fs::copy_options::overwrite_existing);
  }
}

void PrintProgress(std::size_t done, std::size_t total, double seconds, bool last) {
  std::fprintf(stderr, "\rsimulate: frame %zu/%zu, %.1f frames/s%s", done, total,
               seconds > 0.0 ? done / seconds : 0.0, last ? "\n" : "");
  std::fflush(stderr);
}

}  // namespace

bool DatasetWriterOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Nested("render", render);
  check.AtLeast("exposure_time_s", exposure_time_s, 0.0);
  check.InRange("motion_blur_samples", motion_blur_samples, 2, 64, Interval::kClosed);
  check.InRange("png_compression", png_compression, 0, 9, Interval::kClosed);
  check.AtLeast("start_time_ns", start_time_ns, 0);
  return check.ok();
}

DatasetWriterOptions DefaultSensorOptions() {
  DatasetWriterOptions options;
  options.render.noise_sigma = 2.0;
  options.render.exposure_variation = 0.08;
  options.exposure_time_s = 0.0;
  return options;
}

std::int64_t TimestampNs(double time_s, std::int64_t start_time_ns) {
  return start_time_ns + static_cast<std::int64_t>(std::llround(time_s * 1e9));
}

std::vector<Rigid3> ExposurePoses(const std::vector<TimedPose>& poses, std::size_t index,
                                  double exposure_time_s, int samples) {
  if (exposure_time_s <= 0.0 || samples < 2 || poses.size() < 2) {
    return {poses.at(index).world_from_cam};
  }
  std::vector<Rigid3> result;
  const double centre = poses.at(index).time_s;
  for (int k = 0; k < samples; ++k) {
    const double t = std::clamp(centre + exposure_time_s * ((k + 0.5) / samples - 0.5),
                                poses.front().time_s, poses.back().time_s);
    // The segment [j, j + 1] holding t.
    const auto after = std::upper_bound(
        poses.begin(), poses.end(), t,
        [](double time, const TimedPose& pose) { return time < pose.time_s; });
    const std::size_t j = std::min<std::size_t>(
        std::max<std::ptrdiff_t>(after - poses.begin() - 1, 0), poses.size() - 2);
    const double span = poses[j + 1].time_s - poses[j].time_s;
    const double s = span > 0.0 ? std::clamp((t - poses[j].time_s) / span, 0.0, 1.0) : 0.0;
    result.push_back(Interpolate(poses[j].world_from_cam, poses[j + 1].world_from_cam, s));
  }
  return result;
}

DatasetSummary WriteSimulatedSequence(const std::filesystem::path& world_sdf,
                                      const CameraModel& camera,
                                      const std::vector<TimedPose>& poses,
                                      const std::filesystem::path& out_dir,
                                      const DatasetWriterOptions& options) {
  if (!options.Check()) throw InputError("simulate", "invalid dataset writer options");
  if (!camera.Check()) throw InputError("camera", "invalid camera model");
  if (poses.empty()) throw InputError("path", "no camera poses to render");
  const WorldModel world = LoadWorldModel(world_sdf);
  Stopwatch stopwatch;
  RenderOptions render_options = options.render;
  render_options.depth = options.write_depth;
  Renderer renderer(world, camera, render_options);

  StagedDirectory staged(out_dir);
  const fs::path cam_dir = staged.path() / "mav0" / "cam0";
  const fs::path depth_dir = staged.path() / "mav0" / "depth0";
  fs::create_directories(cam_dir / "data");
  if (options.write_depth) fs::create_directories(depth_dir / "data");
  fs::create_directories(staged.path() / "mav0" / "state_groundtruth_estimate0");

  std::string image_csv = "#timestamp [ns],filename\n";
  std::future<void> pending_write;  // PNG encoding of the previous frame overlaps rendering
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (i > 0 && poses[i].time_s <= poses[i - 1].time_s) {
      throw InputError("path", fmt::format("pose {}: time does not increase", i));
    }
    const std::int64_t ns = TimestampNs(poses[i].time_s, options.start_time_ns);
    const std::string name = std::to_string(ns) + ".png";
    RenderedFrame frame = renderer.Render(
        ExposurePoses(poses, i, options.exposure_time_s, options.motion_blur_samples), i,
        poses[i].time_s);
    if (pending_write.valid()) pending_write.get();
    pending_write = std::async(std::launch::async, [&, frame = std::move(frame), name] {
      WritePng(cam_dir / "data" / name, frame.grey, options.png_compression);
      if (options.write_depth) {
        WritePng(depth_dir / "data" / name, DepthMillimetres(frame.depth),
                 options.png_compression);
      }
    });
    image_csv += std::to_string(ns) + "," + name + "\n";
    if (options.progress && (i % 10 == 9 || i + 1 == poses.size())) {
      PrintProgress(i + 1, poses.size(), stopwatch.ElapsedSeconds(), i + 1 == poses.size());
    }
  }
  if (pending_write.valid()) pending_write.get();

  WriteTextFileAtomically(cam_dir / "data.csv", image_csv);
  if (options.write_depth) WriteTextFileAtomically(depth_dir / "data.csv", image_csv);
  WriteEuRoCSensorYaml(camera, cam_dir / "sensor.yaml");
  WriteTextFileAtomically(staged.path() / "mav0" / "state_groundtruth_estimate0" / "data.csv",
                          GroundTruthCsv(poses, options.start_time_ns));
  CopyWorld(world, staged.path());
  staged.Commit();

  DatasetSummary summary;
  summary.frames = poses.size();
  summary.duration_s = poses.back().time_s - poses.front().time_s;
  summary.wall_time_s = stopwatch.ElapsedSeconds();
  summary.frames_per_second = summary.frames / std::max(summary.wall_time_s, 1e-9);
  summary.renderer = renderer.ContextDescription();
  return summary;
}

}  // namespace arucoslam
