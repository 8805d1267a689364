// SDF text for markers, in the subset of docs/sdf_subset.md: one static model per marker (a
// thin box textured with the marker PNG, posed world_from_marker), model.config and a world.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/markers/marker_image.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct MarkerModelSdfOptions {
  // Dictionary of the marker; with `image` it fixes the quiet zone, hence the box side.
  std::string dictionary = "DICT_4X4_50";
  // The PNG used as texture (as DrawMarkerImage draws it): pixels and quiet zone width.
  MarkerImageOptions image;
  // Box thickness along the marker z axis, metres. The printed face (+z of the box) lies
  // in the marker plane, so the box centre sits thickness/2 behind it.
  double thickness = 0.002;
  // Texture path written in <albedo_map>, relative to the SDF file naming it or absolute.
  // Empty: MarkerTextureFileName(id), i.e. the PNG sits beside the SDF file.
  std::string albedo_map;
  // Model name. Empty: MarkerModelName(id).
  std::string model_name;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Nested("image", image);
    check.Above("thickness", thickness, 0.0);
    return check.ok();
  }
};

// "marker_<id>": the model name (and model folder name) of a marker.
std::string MarkerModelName(int id);
// "marker_<id>.png".
std::string MarkerTextureFileName(int id);

// Side of the textured box in metres: the marker side scaled by the PNG's full width over
// the width of its black square (the quiet zone in whole pixels, as DrawMarkerImage draws).
// Throws InputError for an unknown dictionary.
double MarkerBoxSide(double marker_size, const std::string& dictionary,
                     const MarkerImageOptions& image);

// "x y z roll pitch yaw" of an SDF <pose> (extrinsic XYZ: R = Rz(yaw) Ry(pitch) Rx(roll)),
// printed with 17 significant digits so that parsing gives back the same doubles.
std::string SdfPoseText(const Rigid3& parent_from_child);
// Roll, pitch, yaw of a rotation as SDF expects them (pitch in [-pi/2, pi/2]).
Eigen::Vector3d RollPitchYaw(const Eigen::Quaterniond& rotation);

// The <model> element of one marker (no <?xml?> or <sdf> wrapper), so that a world writer
// can inline it; its <pose> is marker.world_from_marker. Throws InputError when the options
// are invalid, the size is not positive or the dictionary is unknown.
std::string MarkerModelSdf(const MarkerInfo& marker, const MarkerModelSdfOptions& options);

// Wraps elements in `<?xml version="1.0"?><sdf version="1.9">...</sdf>`.
std::string SdfDocument(const std::string& elements);

// model.config of a model folder whose model.sdf holds the model `model_name`.
std::string ModelConfigText(const std::string& model_name, const std::string& description);

// A world named `world_name` holding one <include> per URI (such as "model://marker_7")
// and nothing else (no light, no ground): the included models keep the pose written in
// their model.sdf.
std::string WorldWithIncludesSdf(const std::string& world_name,
                                 const std::vector<std::string>& model_uris);

// Fills the existing folder `folder` with one model folder per marker of `map`
// (marker_<id>/model.config, model.sdf, marker_<id>.png: the PNG of DrawMarkerImage with
// `image`) and `world.sdf` including them all as "model://marker_<id>", so `folder` must be
// on the model path (GZ_SIM_RESOURCE_PATH for Gazebo, SDF_PATH for libsdformat; the sim/
// world loader looks beside the world file). `thickness` as in MarkerModelSdfOptions.
// Returns the world file's path. Throws InputError as MarkerModelSdf does.
std::filesystem::path WriteMarkerSdfFolder(const MarkerMap& map,
                                           const std::filesystem::path& folder,
                                           const MarkerImageOptions& image,
                                           double thickness = 0.002);

}  // namespace arucoslam
