// WorldModel: the visual geometry of an SDF world (docs/sdf_subset.md) as a flat list of
// posed primitives (box, plane, cylinder) with colours and textures; the renderer draws it.
#pragma once

#include <Eigen/Core>

#include <filesystem>
#include <string>
#include <vector>

#include "arucoslam/geometry/rigid3.h"

namespace arucoslam {

enum class ShapeType { kBox, kPlane, kCylinder };

// One visual of the world. Shape frame conventions (SDF's):
//   box: centred at the origin, sides `size` (x, y, z);
//   plane: the rectangle |x| <= size.x/2, |y| <= size.y/2 at z = 0, normal +z
//          (SDF's <normal> is folded into world_from_shape);
//   cylinder: axis z, centred at the origin, radius = size.x / 2, length = size.z.
struct WorldPrimitive {
  ShapeType type = ShapeType::kBox;
  std::string name;          // "model::link::visual" (nested models joined by "::")
  Rigid3 world_from_shape;   // metres
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  // metres, see above (plane: size.z = 0)
  // Material colours, RGBA 0..1 (no <material> or no <diffuse>: white; no <ambient>: the
  // diffuse colour). A texture is modulated by them.
  Eigen::Vector4d diffuse{1.0, 1.0, 1.0, 1.0};
  Eigen::Vector4d ambient{1.0, 1.0, 1.0, 1.0};
  std::filesystem::path texture;  // absolute path of the albedo map; empty: untextured

  double radius() const { return 0.5 * size.x(); }  // cylinder only
};

struct WorldModel {
  std::filesystem::path sdf_path;     // the file it was loaded from
  std::string world_name;
  std::vector<WorldPrimitive> primitives;
  // Every file the world is made of besides sdf_path (absolute): included model.sdf and
  // model.config files and textures, each once, so that a copy of the world can be made.
  std::vector<std::filesystem::path> files;
  // Direction the sun's light travels, in the world frame (unit; from the first
  // directional <light> of the world, else a default from above and the side).
  Eigen::Vector3d sun_direction{0.3, 0.2, -0.93};
};

// Parses `sdf_path` with libsdformat 12 (includes of model folders resolved through the
// file's own folder and SDF_PATH / GZ_SIM_RESOURCE_PATH). Geometry outside the subset
// (mesh, sphere, ...) is skipped with a warning. Throws InputError naming the file and
// libsdformat's first error when the file is unreadable or not a world, or names a texture
// that does not exist.
WorldModel LoadWorldModel(const std::filesystem::path& sdf_path);

// Same from an SDF string; relative textures resolve against `base_dir`.
WorldModel LoadWorldModelFromString(const std::string& sdf_text,
                                    const std::filesystem::path& base_dir,
                                    const std::string& source = "<sdf string>");

// Euclidean distance (metres) from a point to the surface of one primitive (0 on it;
// positive inside and outside a solid: distance to the nearest face).
double DistanceToSurface(const WorldPrimitive& primitive, const Eigen::Vector3d& p_in_world);

// Distance to the nearest surface of any primitive; +infinity for an empty world.
// Linear in the number of primitives.
double DistanceToNearestSurface(const WorldModel& world, const Eigen::Vector3d& p_in_world);

}  // namespace arucoslam
