#include "arucoslam/eval/world_surfaces.h"

namespace arucoslam {

std::vector<SurfacePrimitive> SurfacesFromWorldModel(const WorldModel& world) {
  std::vector<SurfacePrimitive> surfaces;
  surfaces.reserve(world.primitives.size());
  for (const WorldPrimitive& primitive : world.primitives) {
    SurfacePrimitive surface;
    surface.world_from_shape = primitive.world_from_shape;
    switch (primitive.type) {
      case ShapeType::kBox:
        surface.shape = SurfaceShape::kBox;
        surface.box_size = primitive.size;
        break;
      case ShapeType::kPlane:
        surface.shape = SurfaceShape::kPlane;
        surface.plane_size = primitive.size.head<2>();
        break;
      case ShapeType::kCylinder:
        surface.shape = SurfaceShape::kCylinder;
        surface.radius = primitive.radius();
        surface.length = primitive.size.z();
        break;
    }
    surfaces.push_back(surface);
  }
  return surfaces;
}

std::vector<SurfacePrimitive> LoadWorldSurfaces(const std::filesystem::path& sdf_path) {
  return SurfacesFromWorldModel(LoadWorldModel(sdf_path));
}

}  // namespace arucoslam
