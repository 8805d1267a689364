// Dataset writer: renders a world along timed camera poses into a sequence folder in the
// EuRoC layout of DESIGN.md (images, data.csv, sensor.yaml, ground truth, markers, world).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/sim/path.h"
#include "arucoslam/sim/renderer.h"

namespace arucoslam {

struct DatasetWriterOptions {
  RenderOptions render;            // lighting, noise, exposure changes, anti-aliasing
  double exposure_time_s = 0.0;    // motion blur window centred on each frame time (0: none)
  int motion_blur_samples = 4;     // renders averaged over the window when it is > 0 (>= 2)
  bool write_depth = false;        // also mav0/depth0/data/<ns>.png: 16-bit, millimetres
  int png_compression = 1;         // zlib level of the PNGs, 0 (fast) .. 9 (small)
  // Timestamp (ns) of time 0 of the path: EuRoC-like 19-digit stamps sort as text too.
  std::int64_t start_time_ns = 1'700'000'000'000'000'000;
  bool progress = true;            // a progress line on stderr while rendering

  bool Check(std::string* why = nullptr) const;
};

struct DatasetSummary {
  std::size_t frames = 0;
  double duration_s = 0.0;        // of the sequence (last minus first timestamp)
  double wall_time_s = 0.0;       // rendering and writing
  double frames_per_second = 0.0;
  std::string renderer;           // OpenGL platform and renderer used
};

// The simulated sensor of `simulate` and of `experiments`/`demo` (one default, so that a
// user's `simulate` + `run` reproduces the experiments): Gaussian noise of 2 grey levels and
// an exposure that drifts by 8% over 12 s; no motion blur.
DatasetWriterOptions DefaultSensorOptions();

// Timestamp in nanoseconds of a path time.
std::int64_t TimestampNs(double time_s, std::int64_t start_time_ns);

// Camera poses over an exposure window centred on poses[index].time_s (linear and slerp
// interpolation between the path's poses, clamped to its ends); one pose when the window
// is zero or `samples` < 2.
std::vector<Rigid3> ExposurePoses(const std::vector<TimedPose>& poses, std::size_t index,
                                  double exposure_time_s, int samples);

// Renders `world_sdf` at every pose and writes the sequence to `out_dir` all-or-nothing
// (built aside, moved into place at the end; an existing `out_dir` is replaced):
//   mav0/cam0/data.csv, mav0/cam0/data/<ns>.png (8-bit grey), mav0/cam0/sensor.yaml,
//   mav0/state_groundtruth_estimate0/data.csv (world_from_cam, q w first, velocity),
//   markers.json (copied from beside the world when present), world.sdf and the files it
//   refers to below its folder (textures, included models), and optionally mav0/depth0.
// Same inputs give byte-identical files. Throws InputError for an unreadable world or a
// bad option, std::runtime_error when OpenGL is unavailable.
DatasetSummary WriteSimulatedSequence(const std::filesystem::path& world_sdf,
                                      const CameraModel& camera,
                                      const std::vector<TimedPose>& poses,
                                      const std::filesystem::path& out_dir,
                                      const DatasetWriterOptions& options = {});

}  // namespace arucoslam
