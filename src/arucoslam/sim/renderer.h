// Renderer: draws a WorldModel through a CameraModel headlessly (OpenGL over EGL, MSAA,
// mipmapped textures, Lambert lighting), with optional distortion, depth, noise and blur.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/sim/world_model.h"

namespace arucoslam {

struct RenderOptions {
  // Multisample anti-aliasing samples per pixel (1 = off). It smooths only polygon
  // silhouettes (textures, markers included, are filtered by mipmaps either way). Mesa 22's
  // llvmpipe offers 4 samples only (2 is rounded up to 4), at about 2.7x the CPU time of
  // no MSAA on the factory (bench/render_bench.cc).
  int msaa_samples = 4;
  // Anisotropic texture filtering where supported (1 = off). Off by default: Mesa 22's
  // llvmpipe shifts oblique texture detail by up to 0.26 px with it (measured by
  // renderer_test's dot plane at 8x), which would bias the ground truth of marker corners.
  double max_anisotropy = 1.0;
  // Lighting (linear intensities; a white Lambert surface facing the sun gets
  // ambient + sun). Ambient is modulated by the material's <ambient>, the rest by <diffuse>.
  double ambient = 0.6;          // uniform light, 0..
  double sun = 0.4;              // directional light along WorldModel::sun_direction, 0..
  double headlight = 0.0;        // point light at the camera (a robot's lamp), 0..
  double headlight_range_m = 4.0;  // distance (m) at which the headlight falls to half
  Eigen::Vector3d background{0.7, 0.7, 0.7};  // RGB 0..1 where nothing is drawn
  double near_m = 0.05;          // clipping distances along the optical axis, metres
  double far_m = 200.0;
  bool frustum_culling = true;   // skip primitives whose bounding sphere is out of view
  bool rgb = false;              // also return the colour image (BGR, 8-bit)
  bool depth = false;            // also return the depth image (z in metres, 32-bit float)
  // Sensor: gain(t) = exposure_gain * (1 + exposure_variation * sin(2 pi t / period)).
  double exposure_gain = 1.0;        // multiplies the rendered intensity, > 0
  double exposure_variation = 0.0;   // relative amplitude of slow exposure changes, [0, 1)
  double exposure_period_s = 12.0;   // period of the exposure changes, seconds (> 0)
  double noise_sigma = 0.0;          // Gaussian sensor noise, grey levels (0..255 scale)
  std::uint64_t noise_seed = 1;      // noise of frame k comes from (noise_seed, k)
  // Distortion (CameraModel other than kNone): a pinhole image this much finer than the
  // output is rendered and remapped through the model.
  double distortion_oversampling = 1.5;

  bool Check(std::string* why = nullptr) const;
};

// One rendered frame; images are camera.height x camera.width.
struct RenderedFrame {
  cv::Mat grey;   // CV_8UC1
  cv::Mat rgb;    // CV_8UC3 (BGR, OpenCV order); empty unless RenderOptions::rgb
  cv::Mat depth;  // CV_32FC1, z along the optical axis in metres, 0 where nothing was hit;
                  // empty unless RenderOptions::depth. Not blurred, no noise.
};

class Renderer {
 public:
  // Creates the OpenGL context and uploads the world (textures decoded here). Throws
  // InputError for a texture that cannot be decoded and std::runtime_error when no OpenGL
  // context can be created. One Renderer per thread; it is used on the creating thread.
  Renderer(const WorldModel& world, const CameraModel& camera, const RenderOptions& options);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Renders the view of a camera at `world_from_cam` (camera x right, y down, z forward).
  // `frame_index` seeds the noise, `time_s` sets the exposure variation.
  RenderedFrame Render(const Rigid3& world_from_cam, std::uint64_t frame_index = 0,
                       double time_s = 0.0);
  // Motion blur: the average of renders at each pose in `world_from_cam_during_exposure`
  // (in time order); depth comes from the middle pose.
  RenderedFrame Render(const std::vector<Rigid3>& world_from_cam_during_exposure,
                       std::uint64_t frame_index = 0, double time_s = 0.0);

  const CameraModel& camera() const;
  // The OpenGL platform, renderer and version in use (e.g. llvmpipe).
  std::string ContextDescription() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

// The 4x4 matrix taking homogeneous points in the camera frame to OpenGL clip coordinates
// so that window coordinates are (u + 0.5, v + 0.5) for the pixel (u, v) of a pinhole
// fx fy cx cy (pixel centres at integers, row 0 at the top, as glReadPixels returns it).
Eigen::Matrix4d ClipFromCamera(double fx, double fy, double cx, double cy, int width,
                               int height, double near_m, double far_m);

}  // namespace arucoslam
