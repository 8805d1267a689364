// `arucoslam locate`: the camera pose in the world from one image and a marker map (the
// computation behind the paper's Table 1), printed as text or, with --json, as JSON.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "arucoslam/exe/command.h"
#include "arucoslam/io/calibration.h"
#include "arucoslam/io/image_file.h"
#include "arucoslam/io/marker_map_json.h"
#include "arucoslam/markers/camera_locator.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/markers/options_visit.h"
#include "arucoslam/markers/preprocess.h"
#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

struct LocateArgs {
  std::string image;
  std::string camera;
  std::string markers;
  bool json = false;
  bool clahe = false;
  std::string refinement = "subpix";
  double inlier_threshold_px = 3.0;
  double upsample = 1.0;
  bool rescue = false;
};

CornerRefinement RefinementFromName(const std::string& name) {
  std::string accepted;
  for (const auto& [refinement, refinement_name] : kCornerRefinementNames) {
    if (refinement_name == name) return refinement;
    accepted += (accepted.empty() ? "" : ", ") + std::string(refinement_name);
  }
  throw InputError("--refinement", "unknown refinement '" + name + "' (accepted: " + accepted + ")");
}

nlohmann::json PoseJson(const Rigid3& pose) {
  const Eigen::Quaterniond& q = pose.rotation;
  return {{"position",
           {{"x", pose.translation.x()}, {"y", pose.translation.y()}, {"z", pose.translation.z()}}},
          {"orientation", {{"x", q.x()}, {"y", q.y()}, {"z", q.z()}, {"w", q.w()}}}};
}

nlohmann::json LocationJson(const CameraLocation& location) {
  nlohmann::json out;
  out["found"] = location.found;
  if (!location.found) out["failure"] = location.failure;
  if (location.found) out["world_from_cam"] = PoseJson(location.world_from_cam);
  if (location.alternative_world_from_cam) {
    out["alternative_world_from_cam"] = PoseJson(*location.alternative_world_from_cam);
  }
  out["markers_used"] = location.marker_ids;
  out["unknown_markers"] = location.unknown_marker_ids;
  out["quality"] = {{"reprojection_rms_px", location.quality.reprojection_rms_px},
                    {"num_markers", location.quality.num_markers},
                    {"num_corners", location.quality.num_corners},
                    {"num_inlier_corners", location.quality.num_inlier_corners},
                    {"ambiguous", location.quality.ambiguous},
                    {"error_ratio", location.quality.error_ratio}};
  return out;
}

std::string IdList(const std::vector<int>& ids) {
  std::string text;
  for (const int id : ids) text += (text.empty() ? "" : ", ") + std::to_string(id);
  return text.empty() ? "none" : text;
}

void PrintText(const CameraLocation& location) {
  if (!location.found) {
    std::printf("no pose: %s\nunknown markers: %s\n", location.failure.c_str(),
                IdList(location.unknown_marker_ids).c_str());
    return;
  }
  const Rigid3& pose = location.world_from_cam;
  const Eigen::Quaterniond& q = pose.rotation;
  std::printf("world_from_cam position (m): %.4f %.4f %.4f\n", pose.translation.x(),
              pose.translation.y(), pose.translation.z());
  std::printf("world_from_cam orientation (x y z w): %.6f %.6f %.6f %.6f\n", q.x(), q.y(), q.z(),
              q.w());
  std::printf("markers used: %s (%d of %d corners inliers, reprojection RMS %.3f px)\n",
              IdList(location.marker_ids).c_str(), location.quality.num_inlier_corners,
              location.quality.num_corners, location.quality.reprojection_rms_px);
  std::printf("unknown markers: %s\n", IdList(location.unknown_marker_ids).c_str());
  if (location.quality.ambiguous) {
    std::printf(
        "warning: ambiguous pose (one marker, IPPE error ratio %.2f); alternative "
        "position %.4f %.4f %.4f\n",
        location.quality.error_ratio, location.alternative_world_from_cam->translation.x(),
        location.alternative_world_from_cam->translation.y(),
        location.alternative_world_from_cam->translation.z());
  }
}

int RunLocate(const LocateArgs& args) {
  const CameraModel camera = ReadCameraModel(args.camera);
  const MarkerMap map = ReadMarkerMapJson(args.markers);
  const cv::Mat image = ReadImageFile(args.image, cv::IMREAD_UNCHANGED);
  if (image.cols != camera.width || image.rows != camera.height) {
    throw InputError(args.image, "image is " + std::to_string(image.cols) + "x" +
                                     std::to_string(image.rows) + " but the calibration " +
                                     args.camera + " is for " + std::to_string(camera.width) + "x" +
                                     std::to_string(camera.height));
  }
  if (!(args.inlier_threshold_px > 0.0)) {
    throw InputError("--inlier-threshold", "expected a positive number of pixels");
  }
  PreprocessOptions preprocess;
  preprocess.clahe = args.clahe;
  DetectorOptions detector_options;
  detector_options.dictionary = map.dictionary;
  detector_options.corner_refinement = RefinementFromName(args.refinement);
  detector_options.upsample = args.upsample;
  detector_options.rescue_rejected = args.rescue;
  if (!detector_options.Check()) throw InputError("--upsample", "expected a factor from 1 to 8");
  const MarkerDetector detector(detector_options);
  CameraLocatorOptions locator;
  locator.inlier_threshold_px = args.inlier_threshold_px;
  const CameraLocation location =
      LocateCamera(detector.Detect(Preprocess(image, preprocess)), map, camera, locator);
  if (args.json) {
    std::printf("%s\n", LocationJson(location).dump(2).c_str());
  } else {
    PrintText(location);
  }
  return location.found ? kExitOk : kExitFailure;
}

}  // namespace

void AddLocateCommand(CLI::App& app, int& exit_status) {
  auto args = std::make_shared<LocateArgs>();
  CLI::App* locate = app.add_subcommand(
      "locate", "Camera pose in the world from one image and a marker map (markers.json)");
  locate->add_option("--image", args->image, "the image (any format OpenCV reads)")->required();
  locate
      ->add_option("--camera", args->camera,
                   "calibration: EuRoC sensor.yaml, ORB-SLAM3 settings or ROS camera_info")
      ->required();
  locate->add_option("--markers", args->markers, "the marker map, markers.json")->required();
  locate->add_flag("--json", args->json, "print the result as JSON");
  locate->add_flag("--clahe", args->clahe, "equalise contrast (CLAHE) before detection");
  locate
      ->add_option("--refinement", args->refinement,
                   "corner refinement: none, subpix (20-60 px markers then refitted to their "
                   "edges), contour or apriltag")
      ->capture_default_str();
  locate
      ->add_option("--inlier-threshold", args->inlier_threshold_px,
                   "reprojection error of an inlier corner, pixels")
      ->capture_default_str();
  locate
      ->add_option("--upsample", args->upsample,
                   "scale the image up before detection (small markers; 2 doubles the cost)")
      ->capture_default_str();
  locate->add_flag("--rescue", args->rescue,
                   "decode again the candidates OpenCV rejects (small or blurred markers)");
  locate->callback([args, &exit_status] { exit_status = RunLocate(*args); });
}

}  // namespace arucoslam
