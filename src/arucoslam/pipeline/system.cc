#include "arucoslam/pipeline/system.h"

#include <stdexcept>
#include <string>
#include <utility>

#include "arucoslam/feature/undistort.h"
#include "arucoslam/pipeline/place_recognition.h"
#include "arucoslam/util/logging.h"

namespace arucoslam {
namespace {

const SystemOptions& Checked(const SystemOptions& options) {
  if (std::string why; !options.Check(&why)) {
    throw std::invalid_argument("System: invalid SystemOptions: " + why);
  }
  return options;
}

}  // namespace

System::System(const CameraModel& camera, const SystemOptions& options)
    : camera_(camera),
      options_(Checked(options)),
      extractor_(options.extractor),
      flow_(camera, options.FlowOptions(), this,
            [this](Map& map) -> std::unique_ptr<PlaceIndex> {
              if (!options_.vocabulary) return nullptr;
              return std::make_unique<PlaceRecognition>(map, options_.vocabulary,
                                                        options_.places, !options_.blocking,
                                                        &stats_.places, &stats_mutex_);
            },
            &stats_, &stats_mutex_) {
  if (options_.marker_map) {
    marker_frontend_ =
        std::make_unique<MarkerFrontend>(camera_, options_.detector, options_.marker_search);
  }
  StartMappingThread();
}

System::~System() { Finish(); }

void System::StartMappingThread() {
  if (options_.blocking) return;
  queue_ = std::make_unique<BoundedQueue<KeyframeId>>(options_.mapper_queue_capacity);
  keyframes_queued_ = 0;
  {
    std::lock_guard lock(mapped_mutex_);
    keyframes_mapped_ = 0;
  }
  mapping_thread_ = std::thread([this] {
    while (const std::optional<KeyframeId> keyframe = queue_->Pop()) {
      gate_.Enter();
      MapKeyframe(*keyframe);
      gate_.Leave();
      mapping_busy_ = false;
      {
        std::lock_guard lock(mapped_mutex_);
        ++keyframes_mapped_;
      }
      mapped_.notify_all();
    }
  });
}

void System::StopMappingThread() {
  if (!mapping_thread_.joinable()) return;
  queue_->Close();
  mapping_thread_.join();
}

void System::Resume() {
  mapping_busy_ = false;
  StartMappingThread();
}

void System::Hold() {
  if (!options_.blocking) gate_.Hold();
}

void System::Release() {
  if (!options_.blocking) gate_.Release();
}

bool System::Idle() const {
  if (options_.blocking) return true;
  // mapping_busy_ is cleared after each keyframe, so a keyframe taken from the queue as the
  // one before it finished reads as idle while it is mapped. Counting it as busy gave fewer
  // keyframes and less accurate threaded runs (BENCHMARKS.md, "Threaded runs").
  return !mapping_busy_ && queue_->Size() == 0;
}

bool System::HasRoom() const {
  return options_.blocking || queue_->Size() < queue_->capacity();
}

bool System::Submit(KeyframeId keyframe) {
  if (options_.blocking) {
    pending_keyframe_ = keyframe;  // mapped once the frame's tracking time is recorded
    return false;
  }
  mapping_busy_ = true;
  if (!queue_->Push(keyframe)) return false;
  ++keyframes_queued_;
  return true;
}

void System::WaitUntilMapped() {
  std::unique_lock lock(mapped_mutex_);
  mapped_.wait(lock, [this] { return keyframes_mapped_ >= keyframes_queued_; });
}

void System::Finish() {
  if (finished_) return;
  finished_ = true;
  StopMappingThread();
  flow_.Finish();
}

void System::StartFromMap(MapData map, bool world_aligned, bool localize_only) {
  if (num_frames_ != 0 || finished_) {
    throw std::logic_error("System::StartFromMap after the first frame");
  }
  if (map.NumKeyframes() == 0) throw std::invalid_argument("System::StartFromMap: empty map");
  flow_.StartFromMap(std::move(map), world_aligned, localize_only);
}

void System::MapKeyframe(KeyframeId keyframe) {
  const Stopwatch watch;
  const LocalMappingResult r = flow_.MapKeyframe(keyframe);
  const bool yielded = r.bundle_adjustment.summary.stopped_early;
  const double elapsed = watch.ElapsedMilliseconds();
  ARUCOSLAM_LOG_DEBUG(
      "keyframe {}: {} culled, {} new ({:.0f} ms), {} fused ({:.0f} ms), BA {} kf {} pts "
      "({} fixed kf, {} residuals, {} iterations{}) rms {:.2f}->{:.2f} px, {} outliers "
      "({:.0f} ms), {} keyframes culled; {:.0f} ms",
      keyframe.value, r.num_culled_points, r.num_new_points, r.triangulation_ms, r.num_fused_points,
      r.fusion_ms, r.bundle_adjustment.num_local_keyframes, r.bundle_adjustment.num_points,
      r.bundle_adjustment.num_fixed_keyframes, r.bundle_adjustment.summary.num_residual_blocks,
      r.bundle_adjustment.summary.num_iterations, yielded ? " (yielded)" : "",
      r.bundle_adjustment.summary.initial_rms_px, r.bundle_adjustment.summary.final_rms_px,
      r.bundle_adjustment.num_erased_observations, r.bundle_adjustment_ms, r.num_culled_keyframes,
      elapsed);
  std::lock_guard lock(stats_mutex_);
  stats_.local_mapping_ms.Add(elapsed);
  stats_.triangulation_ms.Add(r.triangulation_ms);
  stats_.fusion_ms.Add(r.fusion_ms);
  stats_.local_bundle_adjustment_ms.Add(r.bundle_adjustment_ms);
  stats_.culling_ms.Add(r.culling_ms);
  if (yielded) ++stats_.num_yielded_bundle_adjustments;
}

FrameReport System::ProcessImage(const cv::Mat& grey, double timestamp_s) {
  const Stopwatch watch;
  Frame frame;
  frame.id = FrameId(num_frames_);
  frame.timestamp_s = timestamp_s;
  frame.camera = flow_.Camera();
  // Marker detection runs on the worker's thread meanwhile; the frame waits only for what
  // is left of it after extraction.
  if (marker_frontend_) {
    marker_frontend_->StartDetection(grey, *flow_.marker_mapping().LocatingMarkers());
  }
  try {
    frame.features = extractor_.Extract(grey);
  } catch (...) {
    if (marker_frontend_) marker_frontend_->AbandonDetection();
    throw;
  }
  UndistortFeatures(frame.camera, &frame.features);
  frame.ResetMatches();
  const double extraction = watch.ElapsedMilliseconds();
  std::vector<MarkerDetection> detections;
  if (marker_frontend_) detections = marker_frontend_->WaitForDetections();
  FrameReport report = ProcessFrame(std::move(frame), detections);
  if (marker_frontend_) {
    marker_frontend_->RememberFrame(report, flow_.marker_fusion().fix(), detections);
  }
  report.markers = std::move(detections);
  std::lock_guard lock(stats_mutex_);
  stats_.extraction_ms.Add(extraction);
  stats_.frame_ms.Add(watch.ElapsedMilliseconds());
  return report;
}

FrameReport System::ProcessFrame(Frame frame) { return ProcessFrame(std::move(frame), {}); }

FrameReport System::ProcessFrame(Frame frame, const std::vector<MarkerDetection>& detections) {
  if (finished_) throw std::logic_error("System::ProcessFrame after Finish");
  const Stopwatch watch;
  FrameReport report;
  report.index = num_frames_++;
  report.timestamp_s = frame.timestamp_s;
  report.num_features = static_cast<int>(frame.features.size());
  if (frame.map_point_ids.size() != frame.features.size()) frame.ResetMatches();
  LocateWithMarkers(frame, detections, report);
  flow_.Process(frame, report);
  {
    std::lock_guard lock(stats_mutex_);
    ++stats_.num_frames;
    if (report.cam_from_world) ++stats_.num_tracked;
    if (report.state == TrackingState::kLost) ++stats_.num_lost;
    stats_.tracking_ms.Add(watch.ElapsedMilliseconds());
    stats_.marker_fusion = flow_.marker_fusion().stats();
    stats_.map_session = flow_.map_session().stats();
  }
  if (pending_keyframe_) {
    MapKeyframe(*pending_keyframe_);
    pending_keyframe_.reset();
  }
  return report;
}

void System::LocateWithMarkers(Frame& frame, const std::vector<MarkerDetection>& detections,
                               FrameReport& report) {
  if (!marker_frontend_) return;
  OnlineMarkerMapping& marker_mapping = flow_.marker_mapping();
  marker_mapping.AdoptWorldOrigin(detections, frame.camera);
  marker_frontend_->Locate(detections, *marker_mapping.LocatingMarkers(),
                           flow_.Prediction(frame.timestamp_s), report.index, &frame,
                           &flow_.marker_fusion());
  report.num_markers = flow_.marker_fusion().num_markers();
}

SystemStats System::Stats() const {
  std::lock_guard lock(stats_mutex_);
  SystemStats stats = stats_;
  stats.world_anchoring = flow_.anchoring().stats();
  stats.num_whole_map_marker_adjustments =
      flow_.marker_mapping().stats().num_whole_map_adjustments;
  if (marker_frontend_) {
    MarkerFrontendStats markers = marker_frontend_->stats();
    stats.marker_ms = std::move(markers.marker_ms);
    stats.marker_wait_ms = std::move(markers.wait_ms);
    stats.num_full_marker_scans = markers.num_full_scans;
  }
  return stats;
}

}  // namespace arucoslam
