// Converts the simulator's world model (sim/world_model.h, parsed from SDF) into the
// surface primitives that map accuracy measures distances to.
#pragma once

#include <filesystem>
#include <vector>

#include "arucoslam/eval/map_accuracy.h"
#include "arucoslam/sim/world_model.h"

namespace arucoslam {

// One SurfacePrimitive per box, plane and cylinder visual, with the same world pose.
std::vector<SurfacePrimitive> SurfacesFromWorldModel(const WorldModel& world);

// Loads an SDF world (InputError on a bad file) and converts it.
std::vector<SurfacePrimitive> LoadWorldSurfaces(const std::filesystem::path& sdf_path);

}  // namespace arucoslam
