#include "arucoslam/pipeline/place_recognition.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "arucoslam/slam/marker_candidates.h"
#include "arucoslam/util/logging.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

bool PlaceRecognitionOptions::Check(std::string* why) const {
  OptionCheck check(why);
  check.Nested("database", database);
  check.Nested("relocalizer", relocalizer);
  check.Nested("detector", detector);
  check.Nested("closer", closer);
  check.Nested("global_ba", global_ba);
  check.AtLeast("loop_queue_capacity", loop_queue_capacity, 1);
  check.AtLeast("max_marker_candidates", max_marker_candidates, 0);
  return check.ok();
}

PlaceRecognition::PlaceRecognition(Map& map, std::shared_ptr<const Vocabulary> vocabulary,
                                   const PlaceRecognitionOptions& options, bool threaded,
                                   PlaceRecognitionStats* stats, std::mutex* stats_mutex)
    : map_(map),
      vocabulary_(std::move(vocabulary)),
      options_(options),
      threaded_(threaded),
      stats_(stats),
      stats_mutex_(stats_mutex),
      database_(*vocabulary_, options.database),
      relocalizer_(map, database_, options.relocalizer),
      detector_(map, database_, options.detector),
      closer_(map, options.closer) {
  if (!options_.Check()) throw std::invalid_argument("PlaceRecognition: invalid options");
  if (!threaded_) return;
  queue_ = std::make_unique<BoundedQueue<KeyframeId>>(options_.loop_queue_capacity);
  loop_thread_ = std::thread([this] {
    while (const std::optional<KeyframeId> keyframe = queue_->Pop()) DetectAndClose(*keyframe);
  });
  if (options_.loop_closing && options_.global_bundle_adjustment) {
    ba_thread_ = std::thread([this] { GlobalBundleAdjustmentLoop(); });
  }
}

PlaceRecognition::~PlaceRecognition() { Finish(); }

void PlaceRecognition::Finish() {
  if (finished_) return;
  finished_ = true;
  if (loop_thread_.joinable()) {
    queue_->Close();
    loop_thread_.join();
  }
  if (ba_thread_.joinable()) {
    {
      std::lock_guard lock(ba_mutex_);
      ba_stop_ = true;  // a requested run still starts; a later request does not
    }
    ba_wake_.notify_all();
    ba_thread_.join();
  }
}

std::optional<RelocalizationResult> PlaceRecognition::Relocalize(const Frame& frame) {
  const Stopwatch watch;
  std::optional<RelocalizationResult> result;
  {
    std::lock_guard lock(database_mutex_);
    if (database_.size() > 0) result = relocalizer_.Relocalize(frame);
    if (!result && !frame.markers.empty() && options_.max_marker_candidates > 0) {
      const std::vector<KeyframeId> candidates = map_.Read([&](const MapData& data) {
        return KeyframesSeeingMarkers(data, frame.markers, options_.max_marker_candidates);
      });
      result = relocalizer_.RelocalizeAt(frame, candidates);
    }
  }
  std::lock_guard lock(*stats_mutex_);
  ++stats_->num_relocalization_attempts;
  stats_->relocalization_ms.Add(watch.ElapsedMilliseconds());
  return result;
}

void PlaceRecognition::RelocalizationTaken() {
  std::lock_guard lock(*stats_mutex_);
  ++stats_->num_relocalizations;
}

void PlaceRecognition::KeyframeMapped(KeyframeId keyframe) {
  if (threaded_) {
    // Never blocks local mapping: when the loop thread is far behind the keyframe is only
    // added to the database.
    if (!queue_->TryPush(keyframe)) AddToDatabase(keyframe);
    return;
  }
  DetectAndClose(keyframe);
}

void PlaceRecognition::MapMovedExternally() { ++epoch_; }

double PlaceRecognition::KeyframeScale(KeyframeId keyframe) const {
  std::lock_guard lock(scale_mutex_);
  const auto it = keyframe_scales_.find(keyframe);
  return it != keyframe_scales_.end() ? it->second : 1.0;
}

void PlaceRecognition::RecordScaleChanges(const std::map<KeyframeId, double>& changes) {
  std::lock_guard lock(scale_mutex_);
  for (const auto& [id, scale] : changes) {
    const auto [it, added] = keyframe_scales_.emplace(id, scale);
    if (!added) it->second *= scale;
  }
}

void PlaceRecognition::SetMetricMap(bool metric) { closer_.SetMetricMap(metric); }

void PlaceRecognition::IndexExistingKeyframes() {
  const std::vector<KeyframeId> keyframes = map_.Read([](const MapData& data) {
    std::vector<KeyframeId> ids;
    for (const auto& [id, keyframe] : data.keyframes()) ids.push_back(id);
    return ids;
  });
  IndexKeyframes(keyframes);
}

void PlaceRecognition::IndexKeyframes(const std::vector<KeyframeId>& keyframes) {
  for (const KeyframeId& id : keyframes) AddToDatabase(id);
}

void PlaceRecognition::AddToDatabase(KeyframeId keyframe) {
  const std::optional<cv::Mat> descriptors = map_.Read([&](const MapData& data) {
    const Keyframe* found = data.FindKeyframe(keyframe);
    return found ? std::optional<cv::Mat>(found->features.descriptors.clone()) : std::nullopt;
  });
  if (!descriptors) return;
  ImageWords words = database_.Transform(*descriptors);  // the vocabulary is read-only
  std::lock_guard lock(database_mutex_);
  database_.Add(keyframe, std::move(words));
  stored_.push_back(keyframe);
  // Keyframes culled by local mapping leave the database.
  std::vector<KeyframeId> culled;
  map_.Read([&](const MapData& data) {
    for (const KeyframeId& id : stored_) {
      if (data.FindKeyframe(id) == nullptr) culled.push_back(id);
    }
    return 0;
  });
  for (const KeyframeId& id : culled) database_.Erase(id);
  if (!culled.empty()) {
    std::erase_if(stored_, [&](const KeyframeId& id) {
      return std::find(culled.begin(), culled.end(), id) != culled.end();
    });
  }
}

void PlaceRecognition::DetectAndClose(KeyframeId keyframe) {
  const Stopwatch watch;
  AddToDatabase(keyframe);
  if (!options_.loop_closing) return;
  std::vector<KeyframeId> candidates;
  LoopDetectionStats detection;
  {
    std::lock_guard lock(database_mutex_);
    candidates = detector_.DetectByWords(keyframe, &detection);
  }
  const double detection_ms = watch.ElapsedMilliseconds();
  {
    std::lock_guard lock(*stats_mutex_);
    stats_->loop_detection_ms.Add(detection_ms);
    stats_->num_loop_database_matches += detection.num_database_matches;
  }
  for (const KeyframeId& candidate : candidates) {
    const Stopwatch correction;
    LoopClosureResult result;
    {
      std::unique_lock edit = LockMapEdits();  // local mapping waits meanwhile
      result = closer_.CloseLoop(keyframe, candidate);
      if (result.closed) {
        RecordScaleChanges(result.essential_graph.scale_changes);
        ++epoch_;  // a global BA solving the old map must not overwrite the correction
        ++corrections_;
      }
    }
    const double correction_ms = correction.ElapsedMilliseconds();
    if (!result.closed) {
      ARUCOSLAM_LOG_DEBUG("loop {} -> {} rejected: {} ({} matches, {} Sim3 inliers)",
                          keyframe.value, candidate.value, result.reason, result.num_matches,
                          result.num_sim3_inliers);
      std::lock_guard lock(*stats_mutex_);
      ++stats_->num_loop_candidates;
      ++stats_->num_loops_rejected;
      continue;
    }
    ClosedLoop loop;
    map_.Read([&](const MapData& data) {
      if (const Keyframe* k = data.FindKeyframe(keyframe)) loop.current_timestamp_s = k->timestamp_s;
      if (const Keyframe* k = data.FindKeyframe(candidate)) {
        loop.candidate_timestamp_s = k->timestamp_s;
      }
      return 0;
    });
    loop.candidate_from_current = result.candidate_from_current;
    loop.num_inliers = result.num_sim3_inliers + result.num_projected_matches;
    loop.detection_to_corrected_ms = correction_ms;
    ARUCOSLAM_LOG_INFO(
        "loop closed: keyframe {} (t {:.2f} s) -> {} (t {:.2f} s), scale {:.3f}, turn {:.1f} deg, "
        "{} matches, {} fused, {} keyframes in the graph, {:.0f} ms",
        keyframe.value, loop.current_timestamp_s, candidate.value, loop.candidate_timestamp_s,
        result.candidate_from_current.scale, result.correction_rotation_deg, loop.num_inliers,
        result.num_fused_points,
        result.essential_graph.num_keyframes, correction_ms);
    {
      std::lock_guard lock(*stats_mutex_);
      ++stats_->num_loop_candidates;
      stats_->loops.push_back(loop);
      stats_->loop_correction_ms.Add(correction_ms);
    }
    detector_.Reset();
    if (options_.global_bundle_adjustment && closer_.global_bundle_adjustment_requested()) {
      closer_.ClearGlobalBundleAdjustmentRequest();
      RequestGlobalBundleAdjustment();
    }
    break;  // one loop per keyframe
  }
}

void PlaceRecognition::RequestGlobalBundleAdjustment() {
  if (!threaded_) {
    RunGlobalBundleAdjustmentOnce();
    return;
  }
  {
    std::lock_guard lock(ba_mutex_);
    ba_requested_ = true;
  }
  ba_wake_.notify_all();
}

void PlaceRecognition::GlobalBundleAdjustmentLoop() {
  while (true) {
    {
      std::unique_lock lock(ba_mutex_);
      ba_wake_.wait(lock, [&] { return ba_requested_ || ba_stop_; });
      if (!ba_requested_) return;  // stopping with nothing requested
      ba_requested_ = false;
    }
    RunGlobalBundleAdjustmentOnce();
  }
}

void PlaceRecognition::RunGlobalBundleAdjustmentOnce() {
  const Stopwatch watch;
  std::uint64_t epoch = 0;
  GlobalBundleAdjustmentSnapshot snapshot;
  {
    std::unique_lock edit = LockMapEdits();
    epoch = epoch_;
    snapshot = map_.Read([&](const MapData& data) {
      return TakeGlobalSnapshot(data, options_.global_ba, marker_landmarks_,
                                bundle_adjustment_priors_);
    });
  }
  if (snapshot.problem.observations.empty()) return;
  GlobalBundleAdjustmentResult result;
  result.num_keyframes = static_cast<int>(snapshot.keyframe_ids.size());
  result.num_points = static_cast<int>(snapshot.point_ids.size());
  // Tracking and local mapping go on while the solver runs (no lock held).
  result.summary = SolveGlobalSnapshot(options_.global_ba, &snapshot);
  bool applied = false;
  if (result.summary.success) {
    std::unique_lock edit = LockMapEdits();
    if (epoch == epoch_) {
      map_.Write([&](MapData& data) {
        ApplyGlobalBundleAdjustment(data, snapshot, options_.global_ba, &result,
                                    marker_landmarks_);
      });
      applied = true;
      ++corrections_;
    }
  }
  const double elapsed = watch.ElapsedMilliseconds();
  ARUCOSLAM_LOG_INFO("global BA {}: {} keyframes, {} points, {} marker views, rms {:.2f} -> "
                     "{:.2f} px, {} keyframes and {} points added meanwhile, {:.0f} ms",
                     applied ? "applied" : "discarded", result.num_keyframes, result.num_points,
                     snapshot.markers.observations.size(),
                     result.summary.initial_rms_px, result.summary.final_rms_px,
                     result.num_corrected_keyframes, result.num_corrected_points, elapsed);
  std::lock_guard lock(*stats_mutex_);
  if (applied) {
    ++stats_->num_global_bundle_adjustments;
    stats_->global_bundle_adjustment_ms.Add(elapsed);
  } else {
    ++stats_->num_global_bundle_adjustments_discarded;
  }
}

}  // namespace arucoslam
