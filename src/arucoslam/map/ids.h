// Typed ids of the map's entities. Entities refer to each other only by these ids; the Map
// hands them out (frames get theirs from the tracker) and never reuses one.
#pragma once

#include "arucoslam/util/ids.h"

namespace arucoslam {

using FrameId = StrongId<struct FrameIdTag>;
using KeyframeId = StrongId<struct KeyframeIdTag>;
using MapPointId = StrongId<struct MapPointIdTag>;
using MarkerId = StrongId<struct MarkerIdTag, int>;  // the ArUco id of a marker

}  // namespace arucoslam
