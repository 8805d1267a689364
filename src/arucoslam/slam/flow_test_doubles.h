// Test doubles of what FrameFlow and its components are given: InlineMapping (keyframes
// mapped between frames) and ScriptedPlaces (a place database that offers a given pose).
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "arucoslam/slam/place_index.h"

namespace arucoslam::test_doubles {

// Keyframes mapped between frames, as the blocking pipeline does (the caller maps `pending`);
// counts the pauses and holds. `busy` plays a mapper still mapping a keyframe.
class InlineMapping final : public MappingControl {
 public:
  bool Idle() const override { return !busy; }
  bool HasRoom() const override { return true; }
  bool Submit(KeyframeId keyframe) override {
    pending.push_back(keyframe);
    return false;
  }
  void WaitUntilMapped() override {}
  void Pause() override { ++num_pauses; }
  void Resume() override { ++num_resumes; }
  void Hold() override { ++num_holds; }
  void Release() override { ++num_releases; }
  bool YieldRequested() const override { return false; }

  std::vector<KeyframeId> pending;
  bool busy = false;
  int num_pauses = 0;
  int num_resumes = 0;
  int num_holds = 0;
  int num_releases = 0;
};

// A place database that offers the pose it is given (none: nothing found) and counts what
// its caller does with it.

class ScriptedPlaces final : public PlaceIndex {
 public:
  std::optional<RelocalizationResult> Relocalize(const Frame&) override {
    ++num_queries;
    return offer;
  }
  void RelocalizationTaken() override { ++num_taken; }
  void IndexExistingKeyframes() override { ++num_existing_indexed; }
  void IndexKeyframes(const std::vector<KeyframeId>& keyframes) override {
    indexed.insert(indexed.end(), keyframes.begin(), keyframes.end());
  }
  void KeyframeMapped(KeyframeId) override { ++num_mapped; }
  std::unique_lock<std::mutex> LockMapEdits() override { return std::unique_lock(mutex_); }
  void MapMovedExternally() override { ++num_external_moves; }
  void SetMetricMap(bool metric) override { this->metric = metric; }
  void SetMarkerLandmarks(MarkerLandmarks*) override {}
  void SetBundleAdjustmentPriors(std::vector<KeyframePosePrior> priors) override {
    bundle_adjustment_priors = std::move(priors);
  }
  void SetLoopPosePriors(LoopCloser::PosePriorSource, const EssentialGraphOptions&) override {}
  std::uint64_t corrections() const override { return 0; }
  double KeyframeScale(KeyframeId) const override { return 1.0; }
  void RecordScaleChanges(const std::map<KeyframeId, double>&) override {}
  void Finish() override {}

  std::optional<RelocalizationResult> offer;
  int num_queries = 0;
  int num_taken = 0;
  int num_mapped = 0;
  int num_existing_indexed = 0;
  int num_external_moves = 0;
  std::optional<bool> metric;  // the last SetMetricMap
  std::vector<KeyframeId> indexed;
  std::vector<KeyframePosePrior> bundle_adjustment_priors;

 private:
  std::mutex mutex_;
};

}  // namespace arucoslam::test_doubles
