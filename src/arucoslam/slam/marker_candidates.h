// Marker ids as place words for relocalisation: the keyframes that saw the markers a lost
// frame sees, those sharing the most markers first, as candidates to match the frame against.
#pragma once

#include <vector>

#include "arucoslam/map/frame.h"
#include "arucoslam/map/map_data.h"

namespace arucoslam {

// Keyframes of `data` whose stored marker observations (Keyframe::markers) include one of
// `markers`' ids: most shared ids first, then the most recent; at most `max_candidates`.
std::vector<KeyframeId> KeyframesSeeingMarkers(const MapData& data,
                                               const std::vector<MarkerObservation>& markers,
                                               int max_candidates);

}  // namespace arucoslam
