// Constant-velocity prediction of the camera's pose in the marker world from its recent
// marker fixes, used to settle a frame whose own marker location is ambiguous.
#pragma once

#include <deque>
#include <optional>
#include <string>

#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct WorldMotionPriorOptions {
  // A prediction needs a fix at most max_age_s before the frame and an earlier one between
  // min_span_s and max_span_s before that (the velocity's baseline: long enough that a
  // single marker's few centimetres of noise do not dominate it).
  double max_age_s = 0.3;
  double min_span_s = 0.1;
  double max_span_s = 1.0;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.Above("max_age_s", max_age_s, 0.0);
    check.Above("min_span_s", min_span_s, 0.0);
    check.AtLeast("max_span_s", max_span_s, min_span_s, "min_span_s");
    return check.ok();
  }
};

class WorldMotionPrior {
 public:
  explicit WorldMotionPrior(const WorldMotionPriorOptions& options = {}) : options_(options) {}

  // A fix of the frame at `timestamp_s` (increasing); older fixes beyond the span are dropped.
  void Add(double timestamp_s, const Rigid3& world_from_cam);
  void Clear() { fixes_.clear(); }
  // world_from_cam at `timestamp_s` extrapolated from the newest fix with the constant
  // velocity and angular rate between the oldest fix in the span and it; nullopt when the
  // fixes are too old or span too little time.
  std::optional<Rigid3> Predict(double timestamp_s) const;
  // Time of the newest fix (nullopt: none).
  std::optional<double> NewestTimestamp() const {
    return fixes_.empty() ? std::nullopt : std::optional<double>(fixes_.back().timestamp_s);
  }

 private:
  struct Fix {
    double timestamp_s;
    Rigid3 world_from_cam;
  };
  WorldMotionPriorOptions options_;
  std::deque<Fix> fixes_;
};

}  // namespace arucoslam
