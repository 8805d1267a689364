// MarkerMapper: maps markers that the known marker map lacks, online: a marker is mapped once
// several keyframes' IPPE poses of it agree, and refined by BA with the keyframes (culled
// keyframes' marker views are kept at their last pose and join the final refinement).
#pragma once

#include <map>
#include <optional>
#include <set>
#include <vector>

#include "arucoslam/geometry/sim3.h"
#include "arucoslam/map/frame.h"
#include "arucoslam/map/map_data.h"
#include "arucoslam/map/marker_landmark.h"
#include "arucoslam/markers/marker_map.h"
#include "arucoslam/markers/marker_pose.h"
#include "arucoslam/optim/essential_graph.h"
#include "arucoslam/optim/marker_bundle_adjustment.h"
#include "arucoslam/util/option_check.h"

namespace arucoslam {

struct MarkerMapperOptions {
  // Side of the markers absent from the known map, metres. 0: the side of the known map's
  // first marker (no unknown marker is mapped when the known map is empty too).
  double unknown_marker_size_m = 0.0;
  // False: only the known markers' observations are recorded, none is mapped.
  bool map_unknown = true;
  // IPPE ambiguity test of a single view (see marker_pose.h).
  MarkerPoseOptions marker_pose;
  // A keyframe's detection of a mapped marker is kept only when the keyframe's pose sees the
  // marker's printed side within this angle of its normal, degrees (a misread elsewhere).
  double max_view_angle_deg = kMaxReadableViewAngleDeg;
  // ... and when the camera pose the detection itself gives (the nearer IPPE solution, with
  // the marker's mapped pose) lies within this many times the marker's distance of the
  // keyframe's centre: a misread of another marker's pattern (a near marker's id on a far
  // one's corners) puts the camera where no drift explains.
  double max_detection_offset_ratio = 1.0;
  // A first view whose best IPPE solution reprojects worse than this (RMS, pixels) is not
  // used to initialise (blurred or partly occluded corners).
  double max_initial_rms_px = 2.0;
  // A marker is mapped (and written) only once this many keyframes saw it at poses that
  // agree: a false detection of an id rarely repeats at one place (at least 2: a second
  // view also settles IPPE's ambiguity).
  int min_consistent_views = 3;
  // Views agree when the marker centre each one's IPPE pose (composed with the keyframe
  // pose) gives lies within this of the chosen pose's centre: metres, plus a fraction of
  // the view's distance (a single view's depth error grows with it).
  double max_view_disagreement_m = 0.05;
  double max_view_disagreement_fraction = 0.03;
  // Views an unmapped marker keeps (the oldest are dropped first).
  int max_pending_views = 30;
  // Marker views (AddMarkerView): frames posed by markers alone map unknown markers too, so
  // a marker map grows before (or without) a keypoint map in the world. A frame is taken
  // when its
  // camera centre lies at least this fraction of its distance to the nearest located marker
  // from every view taken, or its orientation this many degrees from theirs.
  bool marker_views = true;
  double marker_view_min_translation_fraction = 0.05;
  double marker_view_min_rotation_deg = 5.0;
  // Corner noise given to the bundle adjustment, pixels.
  double corner_sigma_px = 1.0;
  // Refine with the map: after a first solve with corner_sigma_px, the corner sigma is
  // re-estimated from the residuals (BalancedCornerSigmaPx, within these bounds) and the
  // problem solved again when it moved by more than 20%. On the demo sequence the corners
  // fit to 0.33 px RMS and the keypoints to 1.4 px: 1 px under-weighs the markers.
  bool balance_corner_sigma = true;
  double min_corner_sigma_px = 0.1;
  double max_corner_sigma_px = 4.0;
  MarkerBundleAdjustmentOptions bundle_adjustment;
  // Set: the camera rides a ground vehicle on a level floor of the z-up world, and the
  // adjustment of the whole map (Refine) holds every keyframe near one plane (height and
  // mounting tilt estimated with them; GroundPlaneError). Local BA does not use it.
  std::optional<GroundPlanePriorOptions> ground_plane_prior;

  bool Check(std::string* why = nullptr) const {
    OptionCheck check(why);
    check.AtLeast("unknown_marker_size_m", unknown_marker_size_m, 0.0);
    check.Nested("marker_pose", marker_pose);
    check.InRange("max_view_angle_deg", max_view_angle_deg, 0.0, 90.0, Interval::kOpenClosed);
    check.Above("max_detection_offset_ratio", max_detection_offset_ratio, 0.0);
    check.Above("max_initial_rms_px", max_initial_rms_px, 0.0);
    check.AtLeast("min_consistent_views", min_consistent_views, 2);
    check.Above("max_view_disagreement_m", max_view_disagreement_m, 0.0);
    check.AtLeast("max_view_disagreement_fraction", max_view_disagreement_fraction, 0.0);
    check.AtLeast("max_pending_views", max_pending_views, min_consistent_views,
                  "min_consistent_views");
    check.AtLeast("marker_view_min_translation_fraction", marker_view_min_translation_fraction,
                  0.0);
    check.AtLeast("marker_view_min_rotation_deg", marker_view_min_rotation_deg, 0.0);
    check.Above("corner_sigma_px", corner_sigma_px, 0.0);
    check.Above("min_corner_sigma_px", min_corner_sigma_px, 0.0);
    check.AtLeast("max_corner_sigma_px", max_corner_sigma_px, min_corner_sigma_px,
                  "min_corner_sigma_px");
    check.Nested("bundle_adjustment", bundle_adjustment);
    if (ground_plane_prior) check.Nested("ground_plane_prior", *ground_plane_prior);
    return check.ok();
  }
};

// The side of markers absent from `known`: `configured_m` when positive (unknown_marker_size_m),
// else that of the known map's first marker (0 when it is empty too).
double UnknownMarkerSize(const MarkerMap& known, double configured_m);

class MarkerMapper {
 public:
  // `known`: the markers.json map; its markers are kept as they are (fixed or not).
  explicit MarkerMapper(const MarkerMap& known, const MarkerMapperOptions& options = {});

  // Records the markers a keyframe saw (corners in distorted pixels of `camera`) at its
  // current pose estimate in the world; a detection of a landmark that pose cannot have seen
  // (behind the camera, seen from behind or edge-on, or far outside the image), or whose own
  // pose puts the camera too far from it (max_detection_offset_ratio), is a misread and is
  // left out, of the record too. Returns the ids of markers initialised by this view.
  std::vector<MarkerId> AddKeyframe(KeyframeId keyframe, const Rigid3& cam_from_world,
                                    const CameraModel& camera,
                                    const std::vector<MarkerObservation>& markers);
  // A frame posed in the world by markers alone (no keypoint map in the world to give
  // keyframes): taken as a view when it sees a marker the known map lacks or holds as not
  // fixed and lies away from the views taken (marker_view_* options). Its pose stays in the
  // world (no similarity moves it); it maps unknown markers like a keyframe, and joins
  // RefineMarkers and Refine. Returns whether it was taken; `initialised` gets the markers
  // it mapped.
  bool AddMarkerView(const Rigid3& cam_from_world, const CameraModel& camera,
                     const std::vector<MarkerObservation>& markers,
                     std::vector<MarkerId>* initialised);
  int NumMarkerViews() const { return num_marker_views_; }
  // With no marker known and a size for unknown ones: the marker of `detections` that covers
  // the most pixels becomes the world's origin (a fixed landmark at the identity), so that a
  // marker map can start from the markers seen. Returns whether it did (once).
  bool AdoptWorldOrigin(const std::vector<MarkerDetection>& detections, const CameraModel& camera);
  // Keyframes and retired records (marker views too) that saw marker `id`.
  int NumViews(MarkerId id) const;
  // Forgets a keyframe and every marker view it gave.
  void EraseKeyframe(KeyframeId keyframe);
  // Takes the current pose of every recorded keyframe from `map` (optimisation moved them);
  // the ones `map` no longer holds (culled) are retired: their marker views stay, at the
  // last pose, for pending markers and the final refinement.
  void SyncKeyframes(const MapData& map);
  // The map was replaced: every recorded keyframe is retired (its pose is in the world) and
  // later similarity moves no longer apply to them. Returns the closed map's generation.
  int CloseMap();
  // The map of `generation`, closed, was merged into the current one (MapData::Absorb,
  // `new_ids` from it): the records CloseMap retired come back as live keyframes of the
  // current map under their new ids, views and poses unchanged. Returns how many.
  int ReviveClosedMap(int generation, const std::map<KeyframeId, KeyframeId>& new_ids);
  // The current map was moved by `new_from_old` (a world re-alignment): the recorded poses
  // of its keyframes, live and retired, move with it, but those of the keyframes in `stay`
  // when given. (The landmarks are moved by the caller.)
  void ApplySimilarity(const Sim3& new_from_old, const std::set<KeyframeId>* stay = nullptr);

  // Bundle adjustment of every keyframe and point of `map` with the marker observations:
  // known markers fixed, mapped ones estimated. Poses, points and marker poses are written
  // back on success (the keyframe poses this mapper keeps too). One camera for all.
  MarkerBundleAdjustmentSummary Refine(MapData* map);
  // Camera-centre priors on keyframes that Refine adds (the bridge over a tracking gap);
  // those naming no keyframe of the map are skipped.
  void SetPositionPriors(std::vector<KeyframePosePrior> priors) {
    position_priors_ = std::move(priors);
  }
  // Refines the mapped markers against the recorded keyframe poses, live and retired (held
  // fixed), and the marker views that see two markers or more (estimated with them; the
  // refined poses are kept). First every mapped marker whose views another orientation
  // explains clearly better (ReconsiderMappedMarkers) is moved to it.
  MarkerBundleAdjustmentSummary RefineMarkers();

  const MarkerLandmarks& landmarks() const { return landmarks_; }
  // For optimisations that estimate the mapped markers with the keyframes (local BA).
  MarkerLandmarks* mutable_landmarks() { return &landmarks_; }
  bool Records(KeyframeId keyframe) const { return live_.count(keyframe) > 0; }
  int NumRetiredViews() const;
  // Known and mapped markers (mapped ones with fixed: false); pending ones are left out.
  MarkerMap ToMarkerMap() const;
  int NumPending() const { return static_cast<int>(pending_.size()); }

 private:
  // A keyframe's pose and marker views; `keyframe` is invalid once it is retired.
  struct Record {
    KeyframeId keyframe;
    int generation = 0;  // the map it belonged to (see CloseMap)
    Rigid3 cam_from_world;
    CameraModel camera;
    std::vector<MarkerObservation> markers;
    KeyframeId closed_as = KeyframeId();  // the keyframe CloseMap retired it from
  };
  // The generation of marker views: in the world from the start, no map's similarity or
  // merge applies to them.
  static constexpr int kMarkerViewGeneration = -1;
  // Whether a frame at `cam_from_world` seeing `markers` adds a new marker view.
  bool WantsMarkerView(const Rigid3& cam_from_world,
                       const std::vector<MarkerObservation>& markers) const;
  struct View {
    int record = 0;  // into records_
    std::array<Eigen::Vector2d, 4> corners_px;
    MarkerPose pose;  // IPPE in that view
  };

  void Observe(int record, const MarkerObservation& observation,
               std::vector<MarkerId>* initialised);
  void Retire(KeyframeId keyframe);
  // Initialises a pending marker when enough of its views agree; true when it did.
  bool TryInitialise(MarkerId id);
  // Views whose own IPPE marker centre lies near `world_from_marker`'s.
  std::vector<const View*> AgreeingViews(const std::vector<View>& views,
                                         const Rigid3& world_from_marker) const;
  double ViewsSquaredError(const std::vector<const View*>& views,
                           const Rigid3& world_from_marker) const;
  // A mapped marker initialised from few or similar views may sit in the wrong IPPE branch;
  // with more views recorded, each view's solutions are candidates and one whose views'
  // corner error (each view's capped) is under half the current one replaces it. Returns
  // how many moved.
  int ReconsiderMappedMarkers();
  // Bundle adjustment of one new marker against its views' poses (fixed).
  Rigid3 RefineNewMarker(const Rigid3& initial, const std::vector<const View*>& views) const;
  // What each pose, point and marker of a built problem is: the live keyframes' poses come
  // first, then the retired records'.
  struct ProblemIndex {
    std::vector<KeyframeId> keyframes;
    std::vector<int> retired;
    std::vector<MapPointId> points;
    std::vector<MarkerId> markers;
  };
  // With `map`: its keyframes and points, free, and the retired views that see two markers
  // or more (free poses). Without: the recorded poses, live and retired, fixed, but the
  // marker views that see two markers or more (free).
  MarkerBundleAdjustmentProblem BuildProblem(const MapData* map, ProblemIndex* index) const;

  MarkerMapperOptions options_;
  std::string dictionary_;
  double unknown_size_ = 0.0;
  MarkerLandmarks landmarks_;
  std::vector<KeyframePosePrior> position_priors_;
  std::map<int, Record> records_;         // every keyframe recorded, live or retired
  std::map<KeyframeId, int> live_;         // live keyframe -> its record
  int next_record_ = 0;
  int generation_ = 0;
  int num_marker_views_ = 0;
  std::map<MarkerId, std::vector<View>> pending_;
};

}  // namespace arucoslam
