// PlaceIndex: the bag-of-words side of one map as FrameFlow uses it (keyframe database,
// relocalisation, loop closing); implemented with its threads in pipeline/PlaceRecognition.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <vector>

#include "arucoslam/map/frame.h"
#include "arucoslam/map/map.h"
#include "arucoslam/map/marker_landmark.h"
#include "arucoslam/slam/loop_closer.h"
#include "arucoslam/slam/relocalizer.h"

namespace arucoslam {

class PlaceIndex {
 public:
  virtual ~PlaceIndex() = default;

  // Pose of a lost frame from the database (frame features undistorted); nullopt when none.
  virtual std::optional<RelocalizationResult> Relocalize(const Frame& frame) = 0;
  // A pose Relocalize found was taken: counted as a relocalisation.
  virtual void RelocalizationTaken() = 0;
  // Every keyframe already in the map enters the database (a map loaded from a file).
  virtual void IndexExistingKeyframes() = 0;
  // ... or these (keyframes of a map merged into this one).
  virtual void IndexKeyframes(const std::vector<KeyframeId>& keyframes) = 0;
  // A keyframe finished local mapping: it enters the database and the loop detector.
  virtual void KeyframeMapped(KeyframeId keyframe) = 0;
  // Held by local mapping for each keyframe, and by loop closing and world alignment.
  virtual std::unique_lock<std::mutex> LockMapEdits() = 0;
  // The map was moved from outside (world alignment) while holding LockMapEdits: a running
  // global BA is discarded.
  virtual void MapMovedExternally() = 0;
  // The loop closer keeps the monocular scale fixed once the map is metric (markers).
  virtual void SetMetricMap(bool metric) = 0;
  // Once the map is in the marker world: the markers whose corner views join global BA.
  // Call it holding LockMapEdits. Null: keypoints only.
  virtual void SetMarkerLandmarks(MarkerLandmarks* landmarks) = 0;
  // Camera-centre priors that join global BA (the bridge over a tracking gap). Call it
  // holding LockMapEdits, like SetMarkerLandmarks.
  virtual void SetBundleAdjustmentPriors(std::vector<KeyframePosePrior> priors) = 0;
  // ... and the marker pose priors for the loops' essential graphs.
  virtual void SetLoopPosePriors(LoopCloser::PosePriorSource source,
                                 const EssentialGraphOptions& graph) = 0;
  // Incremented by each closed loop and applied global BA.
  virtual std::uint64_t corrections() const = 0;
  // Product of the scale changes that closed loops applied around `keyframe` (1 when none).
  virtual double KeyframeScale(KeyframeId keyframe) const = 0;
  // Multiplies the keyframes' KeyframeScale by a correction's scale changes.
  virtual void RecordScaleChanges(const std::map<KeyframeId, double>& changes) = 0;
  // Waits for queued keyframes and a running global BA; idempotent.
  virtual void Finish() = 0;
};

// Where FrameFlow's keyframes are mapped: inline after the frame (blocking) or on a mapping
// thread behind a bounded queue. Implemented by the pipeline's System.
class MappingControl {
 public:
  virtual ~MappingControl() = default;
  virtual bool Idle() const = 0;     // no keyframe queued or being mapped
  virtual bool HasRoom() const = 0;  // the queue takes another keyframe
  // Hands a keyframe over; true when it was queued for the mapping thread.
  virtual bool Submit(KeyframeId keyframe) = 0;
  // Waits until every keyframe queued so far is mapped.
  virtual void WaitUntilMapped() = 0;
  // Every queued keyframe mapped and mapping stopped, until Resume (the map is replaced
  // meanwhile).
  virtual void Pause() = 0;
  virtual void Resume() = 0;
  // The keyframe being mapped finished and no other started, until Release: the queued ones
  // wait (the map is moved meanwhile, queued keyframes with it).
  virtual void Hold() = 0;
  virtual void Release() = 0;
  // A running local BA should yield: a keyframe waits in the queue, or a hold waits.
  virtual bool YieldRequested() const = 0;
};

}  // namespace arucoslam
