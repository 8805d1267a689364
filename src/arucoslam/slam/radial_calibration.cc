#include "arucoslam/slam/radial_calibration.h"

#include <cmath>

#include "arucoslam/optim/global_bundle_adjustment.h"
#include "arucoslam/optim/radial_refinement.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool RadialCalibrationOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.AtLeast("first_keyframes", first_keyframes, 3);
  check.AtLeast("max_attempts", max_attempts, 0);
  check.AtLeast("min_cost_decrease", min_cost_decrease, 0.0);
  check.Above("max_abs_k", max_abs_k, 0.0);
  check.Nested("solver", solver);
  return check.ok();
}

RadialCalibrationStep RadialCalibration::MaybeRefine(Map& map, CameraModel* camera) {
  RadialCalibrationStep step;
  if (!options_.enabled || num_attempts_ >= options_.max_attempts) return step;
  const std::size_t due = static_cast<std::size_t>(options_.first_keyframes) << num_attempts_;
  if (map.NumKeyframes() < due) return step;
  if (!WithRadialTerm(*camera, 0.0)) return step;
  ++num_attempts_;
  step.attempted = true;
  GlobalBundleAdjustmentOptions global;
  global.solver = options_.solver;
  global.erase_outliers = false;
  GlobalBundleAdjustmentSnapshot plain =
      map.Read([&](const MapData& data) { return TakeGlobalSnapshot(data, global); });
  GlobalBundleAdjustmentSnapshot radial = plain;
  const BundleAdjustmentSummary without = SolveBundleAdjustment(options_.solver, &plain.problem);
  const RadialRefinementSummary with =
      SolveBundleAdjustmentWithRadialTerm(options_.solver, &radial.problem);
  step.k = with.k;
  step.cost_without = without.final_cost;
  step.cost_with = with.solve.final_cost;
  if (!without.success || !with.solve.success) {
    step.message = "solve failed";
    return step;
  }
  const bool pays = step.cost_with <= (1.0 - options_.min_cost_decrease) * step.cost_without;
  if (!pays || std::abs(step.k) > options_.max_abs_k) {
    step.message = pays ? "correction too large" : "correction does not pay";
    return step;
  }
  const std::optional<CameraModel> refined = WithRadialTerm(*camera, step.k);
  GlobalBundleAdjustmentResult applied;
  applied.summary = with.solve;
  map.Write([&](MapData& data) {
    ApplyGlobalBundleAdjustment(data, radial, global, &applied, nullptr);
    data.RecalibrateKeyframes(*refined);
    return 0;
  });
  *camera = *refined;
  step.applied = true;
  step.message = "applied";
  ++num_applied_;
  return step;
}

}  // namespace arucoslam
