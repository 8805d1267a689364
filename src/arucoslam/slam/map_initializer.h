// MapInitializer: each frame before a map exists, against the initialisation reference it
// keeps: the frame becomes the reference, waits, or the two build the first map (from marker
// poses when both have them, else two-view geometry). What the caller carries out is a value.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/map/frame.h"
#include "arucoslam/map/map.h"
#include "arucoslam/slam/initializer.h"
#include "arucoslam/slam/map_initialization.h"
#include "arucoslam/slam/marker_fusion.h"
#include "arucoslam/slam/marker_initialization.h"

namespace arucoslam {

struct MapInitializerOptions {
  InitializerOptions two_view;  // min_matches: fewer features never make a reference
  InitialMapOptions initial_map;
  // The reference is replaced when the current frame is more than this many seconds later
  // (also when too few matches are left). Long enough for a vehicle that starts from rest
  // to build up parallax.
  double max_reference_gap_s = 3.0;
  // When the reference and the frame both have a marker location.
  MarkerInitializationOptions markers;

  bool Check(std::string* why = nullptr) const;
};

// The first two keyframes of a new map.
struct InitialMap {
  Frame first;  // the reference, posed (the second frame is the caller's, posed in place)
  KeyframeId first_id;
  KeyframeId second_id;
  int num_points = 0;
  std::optional<MarkerFix> first_fix;  // the reference's marker location
  bool in_world = false;               // built from marker poses and moved into the marker world
};

// What one frame did: the report's message, whether it was an attempt, a frame the backfill
// keeps (an older reference, or a frame that failed against the reference), the new map.
struct InitializationStep {
  std::string message;
  bool attempted = false;
  std::optional<Frame> for_backfill;
  std::optional<InitialMap> map;
};

class MapInitializer {
 public:
  MapInitializer(const CameraModel& camera, const MapInitializerOptions& options);

  // `frame` (undistorted features, its marker location `fix`) against the reference; `map`
  // must be empty and holds the first map when step.map is set (`frame` is then posed and
  // ready for Tracker::Start). `frame_index` is for the log.
  InitializationStep Step(Map& map, Frame& frame, const std::optional<MarkerFix>& fix,
                          std::size_t frame_index);
  // The map was reset: no reference.
  void Reset();

 private:
  // `frame` becomes the reference; the one it replaces goes to the backfill.
  void ReplaceReference(const Frame& frame, const std::optional<MarkerFix>& fix,
                        InitializationStep* step);
  // Marker initialisation from the reference's and the frame's marker locations: true when
  // it decided the frame (a new reference, a wait for the baseline, a map), false when the
  // two-view initialisation should try.
  bool TryMarkers(Map& map, Frame& frame, const MarkerFix& fix, std::size_t frame_index,
                  InitializationStep* step);
  // The map was built from the reference (posed as `first`): it is handed out and forgotten.
  InitialMap TakeInitialMap(Frame first, const InitialMapResult& created, bool in_world);

  CameraModel camera_;
  MapInitializerOptions options_;
  Initializer two_view_;
  Initializer relaxed_two_view_;  // two_view_ with relaxed_triangulated_fraction
  MarkerInitializer markers_;
  std::optional<Frame> reference_;
  std::optional<MarkerFix> reference_fix_;
};

}  // namespace arucoslam
