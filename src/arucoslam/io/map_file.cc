#include "arucoslam/io/map_file.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <deque>
#include <limits>
#include <map>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

constexpr std::string_view kMagic("ARUCOSLAM-MAP\r\n\x1a", 16);
constexpr std::uint32_t kByteOrderMarker = 0x01020304;
constexpr std::size_t kHeaderBytes = 16 + 4 + 4 + 8;
constexpr std::size_t kTrailerBytes = 8;
// Ids missing between stored ones (entities erased before saving) are skipped on load by
// handing out and dropping placeholder ids. More than 2^20 + 64 per stored entity (a map
// that culled far more than it kept) is treated as corruption.
std::uint64_t MaxSkippedIds(std::size_t num_stored) {
  return (std::uint64_t{1} << 20) + 64 * num_stored;
}

// Appends little-endian numbers and raw bytes.
class ByteWriter {
 public:
  template <typename T>
  void Put(T value) {
    if constexpr (std::is_floating_point_v<T>) {
      using Bits = std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t>;
      PutUnsigned(std::bit_cast<Bits>(value));
    } else {
      PutUnsigned(static_cast<std::make_unsigned_t<T>>(value));
    }
  }
  void PutCount(std::size_t count) {
    if (count > std::numeric_limits<std::uint32_t>::max()) {
      throw std::invalid_argument("SerializeMap: a list is too long for the map format");
    }
    Put(static_cast<std::uint32_t>(count));
  }
  void PutBytes(const void* data, std::size_t size) {
    bytes_.append(static_cast<const char*>(data), size);
  }
  void PutTag(std::string_view tag) { bytes_.append(tag); }
  template <typename Id>
  void PutId(Id id) {
    Put(static_cast<std::uint64_t>(id.value));
  }
  std::string& bytes() { return bytes_; }

 private:
  template <typename U>
  void PutUnsigned(U value) {
    char buffer[sizeof(U)];
    for (std::size_t i = 0; i < sizeof(U); ++i) buffer[i] = static_cast<char>(value >> (8 * i));
    bytes_.append(buffer, sizeof(U));
  }
  std::string bytes_;
};

// Reads what ByteWriter wrote, with bounds checks that throw InputError(source, ...).
class ByteReader {
 public:
  ByteReader(std::string_view bytes, const std::string& source, std::size_t file_offset)
      : bytes_(bytes), source_(source), file_offset_(file_offset) {}

  template <typename T>
  T Get(std::string_view what) {
    if constexpr (std::is_floating_point_v<T>) {
      using Bits = std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t>;
      return std::bit_cast<T>(GetUnsigned<Bits>(what));
    } else {
      return static_cast<T>(GetUnsigned<std::make_unsigned_t<T>>(what));
    }
  }
  // A u32 count of elements of at least `min_element_bytes` each that must fit in the rest.
  std::size_t GetCount(std::size_t min_element_bytes, std::string_view what) {
    const std::size_t count = Get<std::uint32_t>(what);
    if (count * min_element_bytes > Remaining()) {
      throw Corrupt(
          fmt::format("{} {} do not fit in the remaining {} bytes", count, what, Remaining()));
    }
    return count;
  }
  std::string_view GetBytes(std::size_t size, std::string_view what) {
    Need(size, what);
    const std::string_view result = bytes_.substr(position_, size);
    position_ += size;
    return result;
  }
  void ExpectTag(std::string_view tag) {
    if (GetBytes(tag.size(), "section tag") != tag) {
      throw Corrupt(fmt::format("section \"{}\" expected", tag));
    }
  }
  template <typename Id>
  Id GetId(std::string_view what) {
    return Id(static_cast<typename Id::ValueType>(Get<std::uint64_t>(what)));
  }
  std::size_t Remaining() const { return bytes_.size() - position_; }
  InputError Corrupt(const std::string& message) const {
    return InputError(
        source_, fmt::format("corrupt map file at byte {}: {}", file_offset_ + position_, message));
  }

 private:
  void Need(std::size_t size, std::string_view what) {
    if (size > Remaining()) throw Corrupt(fmt::format("{} runs past the end", what));
  }
  template <typename U>
  U GetUnsigned(std::string_view what) {
    Need(sizeof(U), what);
    U value = 0;
    for (std::size_t i = 0; i < sizeof(U); ++i) {
      value |= static_cast<U>(static_cast<std::uint8_t>(bytes_[position_ + i])) << (8 * i);
    }
    position_ += sizeof(U);
    return value;
  }

  std::string_view bytes_;
  const std::string& source_;
  std::size_t file_offset_;
  std::size_t position_ = 0;
};

// ---- Writing ----

void PutDoubles(ByteWriter& out, const std::vector<double>& values) {
  out.PutCount(values.size());
  for (const double value : values) out.Put(value);
}

void PutCamera(ByteWriter& out, const CameraModel& camera) {
  out.Put<std::int32_t>(camera.width);
  out.Put<std::int32_t>(camera.height);
  for (const double value : {camera.fx, camera.fy, camera.cx, camera.cy}) out.Put(value);
  out.Put(static_cast<std::uint8_t>(camera.model));
  for (const double value : camera.distortion) out.Put(value);
  out.Put(camera.rate_hz);
}

void PutPose(ByteWriter& out, const Rigid3& pose) {
  for (int i = 0; i < 4; ++i) out.Put(pose.rotation.coeffs()[i]);  // x y z w
  for (int i = 0; i < 3; ++i) out.Put(pose.translation[i]);
}

void PutFeatures(ByteWriter& out, const OrbFeatures& features) {
  out.Put<std::int32_t>(features.image_width);
  out.Put<std::int32_t>(features.image_height);
  const ScalePyramid& pyramid = features.pyramid;
  out.Put<std::int32_t>(pyramid.num_levels);
  out.Put(pyramid.scale_factor);
  for (const auto* table :
       {&pyramid.scales, &pyramid.inverse_scales, &pyramid.sigma2, &pyramid.inverse_sigma2}) {
    PutDoubles(out, *table);
  }
  out.PutCount(features.keypoints.size());
  for (const cv::KeyPoint& keypoint : features.keypoints) {
    for (const float value :
         {keypoint.pt.x, keypoint.pt.y, keypoint.size, keypoint.angle, keypoint.response}) {
      out.Put(value);
    }
    out.Put<std::int32_t>(keypoint.octave);
    out.Put<std::int32_t>(keypoint.class_id);
  }
  const cv::Mat& descriptors = features.descriptors;
  if (!descriptors.empty() &&
      (descriptors.type() != CV_8U || descriptors.cols != kOrbDescriptorBytes)) {
    throw std::invalid_argument("SerializeMap: descriptors must be 32-byte CV_8U rows");
  }
  out.PutCount(descriptors.empty() ? 0 : descriptors.rows);
  for (int row = 0; row < (descriptors.empty() ? 0 : descriptors.rows); ++row) {
    out.PutBytes(descriptors.ptr<std::uint8_t>(row), kOrbDescriptorBytes);
  }
  out.PutCount(features.undistorted.size());
  for (const Eigen::Vector2d& xy : features.undistorted) {
    out.Put(xy.x());
    out.Put(xy.y());
  }
}

void PutKeyframe(ByteWriter& out, const Keyframe& keyframe, std::uint32_t camera_index) {
  out.PutId(keyframe.id);
  out.PutId(keyframe.frame_id);
  out.Put(keyframe.timestamp_s);
  out.Put(camera_index);
  PutPose(out, keyframe.cam_from_world);
  PutFeatures(out, keyframe.features);
  out.PutCount(keyframe.map_point_ids.size());
  for (const MapPointId& point : keyframe.map_point_ids) out.PutId(point);
  out.PutCount(keyframe.markers.size());
  for (const MarkerObservation& marker : keyframe.markers) {
    out.Put<std::int32_t>(marker.marker_id.value);
    for (const Eigen::Vector2d& corner : marker.corners_px) {
      out.Put(corner.x());
      out.Put(corner.y());
    }
  }
}

void PutMapPoint(ByteWriter& out, const MapPoint& point) {
  out.PutId(point.id);
  for (int i = 0; i < 3; ++i) out.Put(point.p_in_world[i]);
  out.PutBytes(point.descriptor.data(), point.descriptor.size());
  out.PutId(point.reference_keyframe);
  for (int i = 0; i < 3; ++i) out.Put(point.normal[i]);
  out.Put(point.min_distance);
  out.Put(point.max_distance);
  out.Put<std::int32_t>(point.num_visible);
  out.Put<std::int32_t>(point.num_found);
  out.PutCount(point.observations.size());
  for (const auto& [keyframe, index] : point.observations) {
    out.PutId(keyframe);
    out.Put<std::int32_t>(index);
  }
}

// Distinct cameras in keyframe order and each keyframe's index into them.
std::pair<std::vector<std::string>, std::vector<std::uint32_t>> CameraTable(const MapData& data) {
  std::vector<std::string> cameras;
  std::vector<std::uint32_t> indices;
  std::map<std::string, std::uint32_t> index_of;
  for (const auto& [id, keyframe] : data.keyframes()) {
    ByteWriter camera;
    PutCamera(camera, keyframe.camera);
    const auto [it, inserted] =
        index_of.emplace(camera.bytes(), static_cast<std::uint32_t>(cameras.size()));
    if (inserted) cameras.push_back(camera.bytes());
    indices.push_back(it->second);
  }
  return {cameras, indices};
}

// ---- Reading ----

std::vector<double> GetDoubles(ByteReader& in, std::string_view what) {
  std::vector<double> values(in.GetCount(8, what));
  for (double& value : values) value = in.Get<double>(what);
  return values;
}

// Bytes of a stored camera: size, intrinsics, model, distortion, rate.
constexpr std::size_t CameraBytes(int num_distortion) {
  return 4 + 4 + 32 + 1 + 8 * num_distortion + 8;
}
// Distortion coefficients a camera stores in each version, and the last model it knows.
int StoredDistortionCount(std::uint32_t version) {
  return version >= 3 ? kMaxDistortionCoefficients : 5;
}
DistortionModel LastStoredModel(std::uint32_t version) {
  return version >= 3 ? DistortionModel::kTilted : DistortionModel::kEquidistant;
}

CameraModel GetCamera(ByteReader& in, std::uint32_t version) {
  CameraModel camera;
  camera.width = in.Get<std::int32_t>("camera width");
  camera.height = in.Get<std::int32_t>("camera height");
  for (double* value : {&camera.fx, &camera.fy, &camera.cx, &camera.cy}) {
    *value = in.Get<double>("camera intrinsics");
  }
  const auto model = in.Get<std::uint8_t>("camera model");
  if (model > static_cast<std::uint8_t>(LastStoredModel(version))) {
    throw in.Corrupt(fmt::format("unknown camera model {}", model));
  }
  camera.model = static_cast<DistortionModel>(model);
  for (int i = 0; i < StoredDistortionCount(version); ++i) {
    camera.distortion[i] = in.Get<double>("camera distortion");
  }
  camera.rate_hz = in.Get<double>("camera rate");
  return camera;
}

Rigid3 GetPose(ByteReader& in) {
  Rigid3 pose;  // the stored quaternion is kept as is (no re-normalisation): bit-exact
  for (int i = 0; i < 4; ++i) pose.rotation.coeffs()[i] = in.Get<double>("pose");
  for (int i = 0; i < 3; ++i) pose.translation[i] = in.Get<double>("pose");
  return pose;
}

void GetFeatures(ByteReader& in, OrbFeatures& features) {
  features.image_width = in.Get<std::int32_t>("image width");
  features.image_height = in.Get<std::int32_t>("image height");
  ScalePyramid& pyramid = features.pyramid;
  pyramid.num_levels = in.Get<std::int32_t>("pyramid levels");
  pyramid.scale_factor = in.Get<double>("pyramid scale factor");
  for (auto* table :
       {&pyramid.scales, &pyramid.inverse_scales, &pyramid.sigma2, &pyramid.inverse_sigma2}) {
    *table = GetDoubles(in, "pyramid table entries");
  }
  features.keypoints.resize(in.GetCount(28, "keypoints"));
  for (cv::KeyPoint& keypoint : features.keypoints) {
    for (float* value :
         {&keypoint.pt.x, &keypoint.pt.y, &keypoint.size, &keypoint.angle, &keypoint.response}) {
      *value = in.Get<float>("keypoint");
    }
    keypoint.octave = in.Get<std::int32_t>("keypoint octave");
    keypoint.class_id = in.Get<std::int32_t>("keypoint class id");
  }
  const std::size_t rows = in.GetCount(kOrbDescriptorBytes, "descriptors");
  features.descriptors = cv::Mat();
  if (rows > 0) {
    features.descriptors.create(static_cast<int>(rows), kOrbDescriptorBytes, CV_8U);
    const std::string_view block = in.GetBytes(rows * kOrbDescriptorBytes, "descriptors");
    std::memcpy(features.descriptors.data, block.data(), block.size());
  }
  features.undistorted.resize(in.GetCount(16, "undistorted coordinates"));
  for (Eigen::Vector2d& xy : features.undistorted) {
    xy.x() = in.Get<double>("undistorted coordinates");
    xy.y() = in.Get<double>("undistorted coordinates");
  }
}

Keyframe GetKeyframe(ByteReader& in, const std::vector<CameraModel>& cameras) {
  Keyframe keyframe;
  keyframe.id = in.GetId<KeyframeId>("keyframe id");
  keyframe.frame_id = in.GetId<FrameId>("frame id");
  keyframe.timestamp_s = in.Get<double>("timestamp");
  const auto camera_index = in.Get<std::uint32_t>("camera index");
  if (camera_index >= cameras.size()) {
    throw in.Corrupt(fmt::format("keyframe {}: camera {} of {}", keyframe.id.value, camera_index,
                                 cameras.size()));
  }
  keyframe.camera = cameras[camera_index];
  keyframe.cam_from_world = GetPose(in);
  GetFeatures(in, keyframe.features);
  keyframe.map_point_ids.resize(in.GetCount(8, "map point ids"));
  if (keyframe.map_point_ids.size() != keyframe.features.size()) {
    throw in.Corrupt(fmt::format("keyframe {}: {} map point ids for {} keypoints",
                                 keyframe.id.value, keyframe.map_point_ids.size(),
                                 keyframe.features.size()));
  }
  for (MapPointId& point : keyframe.map_point_ids) point = in.GetId<MapPointId>("map point id");
  keyframe.markers.resize(in.GetCount(68, "marker observations"));
  for (MarkerObservation& marker : keyframe.markers) {
    marker.marker_id = MarkerId(in.Get<std::int32_t>("marker id"));
    for (Eigen::Vector2d& corner : marker.corners_px) {
      corner.x() = in.Get<double>("marker corner");
      corner.y() = in.Get<double>("marker corner");
    }
  }
  return keyframe;
}

MapPoint GetMapPoint(ByteReader& in) {
  MapPoint point;
  point.id = in.GetId<MapPointId>("map point id");
  for (int i = 0; i < 3; ++i) point.p_in_world[i] = in.Get<double>("map point position");
  const std::string_view descriptor = in.GetBytes(kOrbDescriptorBytes, "map point descriptor");
  std::memcpy(point.descriptor.data(), descriptor.data(), kOrbDescriptorBytes);
  point.reference_keyframe = in.GetId<KeyframeId>("reference keyframe");
  for (int i = 0; i < 3; ++i) point.normal[i] = in.Get<double>("map point normal");
  point.min_distance = in.Get<double>("min distance");
  point.max_distance = in.Get<double>("max distance");
  point.num_visible = in.Get<std::int32_t>("visible counter");
  point.num_found = in.Get<std::int32_t>("found counter");
  const std::size_t num_observations = in.GetCount(12, "observations");
  for (std::size_t i = 0; i < num_observations; ++i) {
    const auto keyframe = in.GetId<KeyframeId>("observation keyframe");
    const auto index = in.Get<std::int32_t>("observation index");
    if (!point.observations.emplace(keyframe, index).second) {
      throw in.Corrupt(
          fmt::format("map point {}: keyframe {} listed twice", point.id.value, keyframe.value));
    }
  }
  return point;
}

// What the payload holds, before it is rebuilt into a MapData.
constexpr std::uint32_t kWorldAlignedFlag = 1;

struct StoredMap {
  KeyframeId first_keyframe;
  std::vector<Keyframe> keyframes;  // increasing ids
  std::vector<MapPoint> points;     // increasing ids, observations as stored
  std::map<KeyframeId, KeyframeId> parent_of;
  MapFileInfo info;
};

template <typename Id>
void RequireIncreasing(const ByteReader& in, Id previous, Id id, std::string_view what) {
  if (!id.IsValid() || (previous.IsValid() && id <= previous)) {
    throw in.Corrupt(
        fmt::format("{} ids not increasing ({} after {})", what, id.value, previous.value));
  }
}

StoredMap ParsePayload(ByteReader& in, std::uint32_t version) {
  StoredMap stored;
  in.ExpectTag("META");
  const auto flags = in.Get<std::uint32_t>("map flags");
  if ((flags & ~kWorldAlignedFlag) != 0) {
    throw in.Corrupt(fmt::format("unknown map flags {:#x}", flags));
  }
  stored.info.world_aligned = (flags & kWorldAlignedFlag) != 0;
  in.ExpectTag("CAMS");
  std::vector<CameraModel> cameras(
      in.GetCount(CameraBytes(StoredDistortionCount(version)), "cameras"));
  for (CameraModel& camera : cameras) camera = GetCamera(in, version);
  in.ExpectTag("KFRM");
  stored.first_keyframe = in.GetId<KeyframeId>("first keyframe");
  stored.keyframes.resize(in.GetCount(100, "keyframes"));
  KeyframeId previous_keyframe;
  for (Keyframe& keyframe : stored.keyframes) {
    keyframe = GetKeyframe(in, cameras);
    RequireIncreasing(in, previous_keyframe, keyframe.id, "keyframe");
    previous_keyframe = keyframe.id;
  }
  in.ExpectTag("MPTS");
  stored.points.resize(in.GetCount(120, "map points"));
  MapPointId previous_point;
  for (MapPoint& point : stored.points) {
    point = GetMapPoint(in);
    RequireIncreasing(in, previous_point, point.id, "map point");
    previous_point = point.id;
  }
  in.ExpectTag("TREE");
  const std::size_t num_edges = in.GetCount(16, "spanning-tree edges");
  for (std::size_t i = 0; i < num_edges; ++i) {
    const auto child = in.GetId<KeyframeId>("spanning-tree child");
    const auto parent = in.GetId<KeyframeId>("spanning-tree parent");
    if (!stored.parent_of.emplace(child, parent).second) {
      throw in.Corrupt(fmt::format("keyframe {} has two spanning-tree parents", child.value));
    }
  }
  if (in.Remaining() != 0) throw in.Corrupt("unexpected bytes after the last section");
  return stored;
}

// Little-endian unsigned number of `num_bytes` bytes at `offset` (bounds checked by callers).
std::uint64_t ReadLittleEndian(std::string_view bytes, std::size_t offset, std::size_t num_bytes) {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < num_bytes; ++i) {
    value |= static_cast<std::uint64_t>(static_cast<std::uint8_t>(bytes[offset + i])) << (8 * i);
  }
  return value;
}

// Checks magic, byte order, version, size and checksum; returns the payload and sets `version`.
std::string_view CheckEnvelope(std::string_view bytes, const std::string& source,
                               std::uint32_t* version) {
  const std::size_t size = bytes.size();
  const std::size_t magic_bytes = std::min(size, kMagic.size());
  if (bytes.substr(0, magic_bytes) != kMagic.substr(0, magic_bytes)) {
    throw InputError(source, "not an arucoslam map (the file does not start with its magic bytes)");
  }
  if (size < kHeaderBytes) {
    throw InputError(source, fmt::format("truncated map file: ends after {} bytes, expected at "
                                         "least {} (the header)",
                                         size, kHeaderBytes));
  }
  const auto marker = ReadLittleEndian(bytes, 16, 4);
  if (marker != kByteOrderMarker) {
    throw InputError(source, fmt::format("corrupt map header: byte-order marker {:#010x}, "
                                         "expected {:#010x}",
                                         marker, kByteOrderMarker));
  }
  *version = static_cast<std::uint32_t>(ReadLittleEndian(bytes, 20, 4));
  if (*version < kOldestMapFormatVersion || *version > kMapFormatVersion) {
    throw InputError(source, fmt::format("map format version {}, this build reads {} to {}",
                                         *version, kOldestMapFormatVersion, kMapFormatVersion));
  }
  const std::uint64_t payload_bytes = ReadLittleEndian(bytes, 24, 8);
  const std::uint64_t limit = std::numeric_limits<std::uint64_t>::max() - kHeaderBytes - 8;
  if (payload_bytes > limit) {
    throw InputError(source, fmt::format("corrupt map header: payload of {} bytes", payload_bytes));
  }
  const std::uint64_t expected = kHeaderBytes + payload_bytes + kTrailerBytes;
  if (size < expected) {
    throw InputError(source, fmt::format("truncated map file: ends after {} bytes, expected {}",
                                         size, expected));
  }
  if (size > expected) {
    throw InputError(
        source, fmt::format("map file has {} bytes, expected {} (trailing data)", size, expected));
  }
  const std::uint64_t stored = ReadLittleEndian(bytes, expected - kTrailerBytes, 8);
  const std::uint64_t computed = Fnv1a64(bytes.substr(0, expected - kTrailerBytes));
  if (stored != computed) {
    throw InputError(source, fmt::format("map file checksum mismatch (stored {:#018x}, computed "
                                         "{:#018x}): the file is corrupted",
                                         stored, computed));
  }
  return bytes.substr(kHeaderBytes, payload_bytes);
}

// Adds the stored points, then the keyframes (which re-create the observations and the
// covisibility weights), keeping every id: ids missing in between are handed out and dropped.
void AddEntities(const StoredMap& stored, MapData& data, const std::string& source) {
  const auto fail = [&](const std::string& message) {
    return InputError(source, "inconsistent map file: " + message);
  };
  if (!stored.points.empty() && stored.points.back().id.value + 1 - stored.points.size() >
                                    MaxSkippedIds(stored.points.size())) {
    throw fail("map point ids skip too many values");
  }
  std::uint64_t next_point = 0;
  for (const MapPoint& point : stored.points) {
    for (; next_point < point.id.value; ++next_point) data.EraseMapPoint(data.AddMapPoint({}));
    if (data.AddMapPoint(point) != point.id) throw fail("map point ids out of order");
    ++next_point;
  }
  if (!stored.keyframes.empty() &&
      (stored.keyframes.front().id != KeyframeId(0) || stored.first_keyframe != KeyframeId(0))) {
    throw fail("the first keyframe must have id 0");
  }
  if (!stored.keyframes.empty() && stored.keyframes.back().id.value + 1 - stored.keyframes.size() >
                                       MaxSkippedIds(stored.keyframes.size())) {
    throw fail("keyframe ids skip too many values");
  }
  std::uint64_t next_keyframe = 0;
  for (const Keyframe& keyframe : stored.keyframes) {
    for (; next_keyframe < keyframe.id.value; ++next_keyframe) {
      data.EraseKeyframe(data.AddKeyframe(Keyframe()));
    }
    if (data.AddKeyframe(keyframe) != keyframe.id) throw fail("keyframe ids out of order");
    ++next_keyframe;
    if (data.FindKeyframe(keyframe.id)->map_point_ids != keyframe.map_point_ids) {
      throw fail(fmt::format("keyframe {}: map point ids name unknown or repeated points",
                             keyframe.id.value));
    }
  }
  for (const MapPoint& point : stored.points) {
    if (data.FindMapPoint(point.id)->observations != point.observations) {
      throw fail(
          fmt::format("map point {}: observations differ from the keyframes' map point "
                      "ids",
                      point.id.value));
    }
  }
}

// Re-attaches every keyframe to its stored parent, from the root down, so that no step can
// make a cycle.
void RestoreSpanningTree(const StoredMap& stored, MapData& data, const std::string& source) {
  const auto fail = [&](const std::string& message) {
    return InputError(source, "inconsistent map file: spanning tree: " + message);
  };
  std::map<KeyframeId, std::vector<KeyframeId>> children;
  for (const auto& [child, parent] : stored.parent_of) {
    if (data.FindKeyframe(child) == nullptr || data.FindKeyframe(parent) == nullptr) {
      throw fail(fmt::format("edge {}-{} names an unknown keyframe", child.value, parent.value));
    }
    children[parent].push_back(child);
  }
  if (stored.keyframes.empty()) return;
  if (stored.parent_of.count(data.FirstKeyframe()) != 0) throw fail("the root has a parent");
  std::size_t reached = 1;
  std::deque<KeyframeId> queue = {data.FirstKeyframe()};
  while (!queue.empty()) {
    const KeyframeId parent = queue.front();
    queue.pop_front();
    for (const KeyframeId& child : children[parent]) {
      if (!data.SetSpanningTreeParent(child, parent)) {
        throw fail(fmt::format("keyframe {} cannot take parent {}", child.value, parent.value));
      }
      queue.push_back(child);
      ++reached;
    }
  }
  if (reached != stored.keyframes.size()) {
    throw fail(
        fmt::format("{} of {} keyframes hang from the root", reached, stored.keyframes.size()));
  }
}

}  // namespace

std::uint64_t Fnv1a64(std::string_view bytes) {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (const char byte : bytes) {
    hash ^= static_cast<std::uint8_t>(byte);
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

std::string SerializeMap(const MapData& data, const MapFileInfo& info) {
  const auto [cameras, camera_indices] = CameraTable(data);
  ByteWriter out;
  out.PutTag(kMagic);
  out.Put(kByteOrderMarker);
  out.Put(kMapFormatVersion);
  out.Put<std::uint64_t>(0);  // payload size, patched below
  out.PutTag("META");
  out.Put<std::uint32_t>(info.world_aligned ? kWorldAlignedFlag : 0);
  out.PutTag("CAMS");
  out.PutCount(cameras.size());
  for (const std::string& camera : cameras) out.PutBytes(camera.data(), camera.size());
  out.PutTag("KFRM");
  out.PutId(data.FirstKeyframe());
  out.PutCount(data.NumKeyframes());
  std::size_t k = 0;
  for (const auto& [id, keyframe] : data.keyframes()) {
    PutKeyframe(out, keyframe, camera_indices[k++]);
  }
  out.PutTag("MPTS");
  out.PutCount(data.NumMapPoints());
  for (const auto& [id, point] : data.map_points()) PutMapPoint(out, point);
  out.PutTag("TREE");
  std::vector<std::pair<KeyframeId, KeyframeId>> edges;
  for (const auto& [id, keyframe] : data.keyframes()) {
    const KeyframeId parent = data.covisibility().Parent(id);
    if (parent.IsValid()) edges.emplace_back(id, parent);
  }
  out.PutCount(edges.size());
  for (const auto& [child, parent] : edges) {
    out.PutId(child);
    out.PutId(parent);
  }
  std::string& bytes = out.bytes();
  const std::uint64_t payload_bytes = bytes.size() - kHeaderBytes;
  for (std::size_t i = 0; i < 8; ++i) {
    bytes[kHeaderBytes - 8 + i] = static_cast<char>(payload_bytes >> (8 * i));
  }
  out.Put(Fnv1a64(bytes));
  return std::move(bytes);
}

MapData DeserializeMap(std::string_view bytes, const std::string& source, MapFileInfo* info) {
  std::uint32_t version = 0;
  const std::string_view payload = CheckEnvelope(bytes, source, &version);
  ByteReader reader(payload, source, kHeaderBytes);
  StoredMap stored = ParsePayload(reader, version);
  MapData data;
  AddEntities(stored, data, source);
  RestoreSpanningTree(stored, data, source);
  const std::string violation = data.CheckInvariants();
  if (!violation.empty()) throw InputError(source, "inconsistent map file: " + violation);
  if (info != nullptr) *info = stored.info;
  return data;
}

void SaveMapFile(const MapData& data, const std::filesystem::path& path, const MapFileInfo& info) {
  WriteTextFileAtomically(path, SerializeMap(data, info));
}

void SaveMapFile(const Map& map, const std::filesystem::path& path, const MapFileInfo& info) {
  const std::string bytes =
      map.Read([&info](const MapData& data) { return SerializeMap(data, info); });
  WriteTextFileAtomically(path, bytes);
}

MapData LoadMapFile(const std::filesystem::path& path, MapFileInfo* info) {
  RequireFile(path, "map file");
  return DeserializeMap(ReadTextFile(path), path.string(), info);
}

void LoadMapFile(const std::filesystem::path& path, Map& map, MapFileInfo* info) {
  MapData loaded = LoadMapFile(path, info);
  map.Write([&loaded](MapData& data) { data = std::move(loaded); });
}

}  // namespace arucoslam
