#include "arucoslam/slam/map_initializer.h"

#include <utility>

#include "arucoslam/util/logging.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool MapInitializerOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Nested("two_view", two_view);
  check.Nested("initial_map", initial_map);
  check.Above("max_reference_gap_s", max_reference_gap_s, 0.0);
  check.Nested("markers", markers);
  return check.ok();
}

MapInitializer::MapInitializer(const CameraModel& camera, const MapInitializerOptions& options)
    : camera_(camera),
      options_(options),
      two_view_(options.two_view),
      relaxed_two_view_([&] {
        InitializerOptions relaxed = options.two_view;
        relaxed.min_triangulated_fraction = relaxed.relaxed_triangulated_fraction;
        return relaxed;
      }()),
      markers_(options.markers, options.two_view, options.initial_map) {}

InitializationStep MapInitializer::Step(Map& map, Frame& frame, const std::optional<MarkerFix>& fix,
                                        std::size_t frame_index) {
  InitializationStep step;
  const bool enough = static_cast<int>(frame.features.size()) >= options_.two_view.min_matches;
  if (!reference_ || frame.timestamp_s - reference_->timestamp_s > options_.max_reference_gap_s) {
    if (enough) ReplaceReference(frame, fix, &step);
    step.message = enough ? "initialisation reference" : "too few features";
    return step;
  }
  step.attempted = true;
  if (fix && TryMarkers(map, frame, *fix, frame_index, &step)) return step;
  const bool waited =
      frame.timestamp_s - reference_->timestamp_s >= options_.two_view.relax_after_s;
  const InitializationResult result =
      (waited ? relaxed_two_view_ : two_view_)
          .Initialize(reference_->features, frame.features, camera_);
  step.message = result.message;
  ARUCOSLAM_LOG_DEBUG("frame {}: initialisation {}: {}", frame_index,
                      result.success ? "succeeded" : InitFailureName(result.failure),
                      result.message);
  if (!result.success) {
    if (result.failure == InitFailure::kTooFewMatches && enough) {
      ReplaceReference(frame, fix, &step);
    } else {
      step.for_backfill = frame;
    }
    return step;
  }
  Frame first = *reference_;
  const InitialMapResult created =
      CreateInitialMap(map, first, frame, result, options_.initial_map);
  if (!created.success) {
    step.message = created.message;
    return step;
  }
  step.map = TakeInitialMap(std::move(first), created, /*in_world=*/false);
  return step;
}

bool MapInitializer::TryMarkers(Map& map, Frame& frame, const MarkerFix& fix,
                                std::size_t frame_index, InitializationStep* step) {
  if (!reference_fix_) {
    // A reference with a marker location allows the metric initialisation.
    if (static_cast<int>(frame.features.size()) < options_.two_view.min_matches) return false;
    ReplaceReference(frame, fix, step);
    step->message = "initialisation reference (markers)";
    return true;
  }
  Frame first = *reference_;
  const MarkerInitializationResult result = markers_.Initialize(
      map, first, frame, reference_fix_->world_from_cam, fix.world_from_cam, frame_index);
  switch (result.status) {
    case MarkerInitializationStatus::kShortBaseline:
      step->message = result.message;
      return true;
    case MarkerInitializationStatus::kRefused:
      return false;
    case MarkerInitializationStatus::kUnaligned:
    case MarkerInitializationStatus::kInWorld:
      break;
  }
  step->map = TakeInitialMap(std::move(first), result.map,
                             result.status == MarkerInitializationStatus::kInWorld);
  return true;
}

void MapInitializer::ReplaceReference(const Frame& frame, const std::optional<MarkerFix>& fix,
                                      InitializationStep* step) {
  if (reference_) step->for_backfill = std::move(*reference_);
  reference_ = frame;
  reference_fix_ = fix;
}

InitialMap MapInitializer::TakeInitialMap(Frame first, const InitialMapResult& created,
                                          bool in_world) {
  InitialMap initial;
  initial.first = std::move(first);
  initial.first_id = created.first;
  initial.second_id = created.second;
  initial.num_points = created.num_points;
  initial.first_fix = std::move(reference_fix_);
  initial.in_world = in_world;
  Reset();
  return initial;
}

void MapInitializer::Reset() {
  reference_.reset();
  reference_fix_.reset();
}

}  // namespace arucoslam
