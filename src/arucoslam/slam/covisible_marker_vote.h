// CovisibleMarkerVote: settles the ambiguity of a camera located by one known marker through
// the other markers seen with it, which are static: from two frames with different viewpoints
// only their true camera poses put those markers' centres at the same world points.
#pragma once

#include <deque>
#include <string>
#include <vector>

#include "arucoslam/geometry/camera.h"
#include "arucoslam/geometry/rigid3.h"
#include "arucoslam/markers/camera_locator.h"
#include "arucoslam/markers/detector.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct CovisibleMarkerVoteOptions {
  // Ambiguous frames kept to vote with (the oldest are dropped first).
  int max_frames = 30;
  // A marker centre agrees between two frames within this distance: metres plus a fraction
  // of its distance from the cameras (a single view's depth error grows with it).
  double max_disagreement_m = 0.005;
  double max_disagreement_fraction = 0.03;
  // A pair of frames votes for a solution of the new frame when its best pair of solutions
  // puts at least this many more markers in agreement than the best pair with the new
  // frame's other solution (close viewpoints agree either way and do not vote).
  int min_agreement_margin = 3;
  // The new frame is settled when this many earlier frames vote for one solution and none
  // for the other.
  int min_votes = 2;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("max_frames", max_frames, 1);
    check.Above("max_disagreement_m", max_disagreement_m, 0.0);
    check.AtLeast("max_disagreement_fraction", max_disagreement_fraction, 0.0);
    check.AtLeast("min_agreement_margin", min_agreement_margin, 1);
    check.AtLeast("min_votes", min_votes, 1);
    check.AtLeast("max_frames", max_frames, min_votes, "min_votes");
    return check.ok();
  }
};

class CovisibleMarkerVote {
 public:
  explicit CovisibleMarkerVote(const CovisibleMarkerVoteOptions& options = {})
      : options_(options) {}

  // An ambiguous one-marker `location` (alternative_world_from_cam set) and the frame's
  // detections of markers absent from the known map, of side `unknown_size` metres. The
  // frame is kept for later votes; returns the solution the earlier frames settle on.
  AmbiguityChoice Add(const CameraLocation& location,
                      const std::vector<MarkerDetection>& unknown, double unknown_size,
                      const CameraModel& camera);
  // A frame was located without ambiguity: the kept frames are no longer needed.
  void Clear() { frames_.clear(); }
  int NumFrames() const { return static_cast<int>(frames_.size()); }

 private:
  struct Centre {
    int id = -1;
    Eigen::Vector3d in_cam;
  };
  struct AmbiguousFrame {
    Rigid3 world_from_cam[2];  // best, alternative
    std::vector<Centre> centres;  // sorted by id
  };
  // Markers whose centres agree when `a` is at `world_from_a` and `b` at `world_from_b`.
  int Agreeing(const AmbiguousFrame& a, const Rigid3& world_from_a, const AmbiguousFrame& b,
               const Rigid3& world_from_b) const;

  CovisibleMarkerVoteOptions options_;
  std::deque<AmbiguousFrame> frames_;
};

}  // namespace arucoslam
