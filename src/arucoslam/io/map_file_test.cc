#include "arucoslam/io/map_file.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

CameraModel TestCamera(DistortionModel model) {
  CameraModel camera;
  camera.width = 752;
  camera.height = 480;
  camera.fx = 458.654;
  camera.fy = 457.296;
  camera.cx = 367.215;
  camera.cy = 248.375;
  camera.model = model;
  camera.distortion = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05, 0.0};
  camera.rate_hz = 20.0;
  return camera;
}

// A keyframe with random keypoints, descriptors and undistorted coordinates at a random pose.
Keyframe RandomKeyframe(int num_keypoints, const CameraModel& camera, std::mt19937& random) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Keyframe keyframe;
  keyframe.frame_id = FrameId(random() % 1000);
  keyframe.timestamp_s = 1403636579.763555527 + uniform(random);
  keyframe.camera = camera;
  Vector6d tangent;
  for (int i = 0; i < 6; ++i) tangent[i] = uniform(random);
  keyframe.cam_from_world = Rigid3::Exp(tangent);
  OrbFeatures& features = keyframe.features;
  features.image_width = camera.width;
  features.image_height = camera.height;
  features.pyramid = ScalePyramid::Make(8, 1.2);
  features.descriptors = cv::Mat(num_keypoints, kOrbDescriptorBytes, CV_8U);
  for (int i = 0; i < num_keypoints; ++i) {
    cv::KeyPoint keypoint(static_cast<float>(376 + 300 * uniform(random)),
                          static_cast<float>(240 + 200 * uniform(random)), 31.0f,
                          static_cast<float>(180 + 179 * uniform(random)),
                          static_cast<float>(50 + 40 * uniform(random)), i % 8, i);
    features.keypoints.push_back(keypoint);
    features.undistorted.emplace_back(uniform(random), uniform(random));
    for (int b = 0; b < kOrbDescriptorBytes; ++b) {
      features.descriptors.at<std::uint8_t>(i, b) = random() & 0xff;
    }
  }
  keyframe.map_point_ids.assign(num_keypoints, MapPointId());
  return keyframe;
}

// A map built through MapData's API, with id gaps (erased points and a keyframe), two cameras,
// markers, updated descriptors/normals/counters and a hand-set spanning-tree parent.
MapData BuildTestMap(int num_keyframes, int num_keypoints, int num_points, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  MapData data;
  std::vector<MapPointId> points;
  for (int j = 0; j < num_points; ++j) {
    MapPoint point;
    point.p_in_world = Eigen::Vector3d(4 * uniform(random), 2 * uniform(random), 5);
    point.reference_keyframe = KeyframeId(j % num_keyframes);  // ids the keyframes will get
    points.push_back(data.AddMapPoint(point));
  }
  std::vector<KeyframeId> keyframes;
  for (int k = 0; k < num_keyframes; ++k) {
    const CameraModel camera =
        TestCamera(k % 2 == 0 ? DistortionModel::kRadTan : DistortionModel::kEquidistant);
    Keyframe keyframe = RandomKeyframe(num_keypoints, camera, random);
    if (k % 3 == 1) {
      MarkerObservation marker;
      marker.marker_id = MarkerId(7 + k);
      for (auto& corner : marker.corners_px) corner = Eigen::Vector2d(uniform(random), k);
      keyframe.markers.push_back(marker);
    }
    // Each keyframe sees a sliding window of points, keypoint i -> point (k * step + i).
    const int step = num_points / (2 * num_keyframes) + 1;
    for (int i = 0; i < num_keypoints && k * step + i < num_points; i += 1 + (i % 2)) {
      keyframe.map_point_ids[i] = points[k * step + i];
    }
    keyframes.push_back(data.AddKeyframe(keyframe));
  }
  // Gaps in the ids: erase a middle keyframe and a few points.
  EXPECT_TRUE(data.EraseKeyframe(keyframes[num_keyframes / 2]));
  for (int j = 3; j < num_points; j += 11) data.EraseMapPoint(points[j]);
  for (const auto& [id, point] : std::map<MapPointId, MapPoint>(data.map_points())) {
    data.UpdateDescriptor(id);
    data.UpdateNormalAndDepth(id);
    data.IncreaseVisible(id, static_cast<int>(id.value % 5));
    data.IncreaseFound(id, static_cast<int>(id.value % 3));
  }
  EXPECT_TRUE(data.SetSpanningTreeParent(data.LastKeyframe(), data.FirstKeyframe()));
  EXPECT_EQ(data.CheckInvariants(), "");
  return data;
}

template <typename T>
auto Bits(T value) {
  return std::bit_cast<std::conditional_t<sizeof(T) == 8, std::uint64_t, std::uint32_t>>(value);
}

void ExpectCamerasEqual(const CameraModel& a, const CameraModel& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(Bits(a.fx), Bits(b.fx));
  EXPECT_EQ(Bits(a.fy), Bits(b.fy));
  EXPECT_EQ(Bits(a.cx), Bits(b.cx));
  EXPECT_EQ(Bits(a.cy), Bits(b.cy));
  EXPECT_EQ(a.model, b.model);
  EXPECT_EQ(a.distortion, b.distortion);
  EXPECT_EQ(Bits(a.rate_hz), Bits(b.rate_hz));
}

void ExpectFeaturesEqual(const OrbFeatures& a, const OrbFeatures& b) {
  EXPECT_EQ(a.image_width, b.image_width);
  EXPECT_EQ(a.image_height, b.image_height);
  EXPECT_EQ(a.pyramid.num_levels, b.pyramid.num_levels);
  EXPECT_EQ(Bits(a.pyramid.scale_factor), Bits(b.pyramid.scale_factor));
  EXPECT_EQ(a.pyramid.scales, b.pyramid.scales);
  EXPECT_EQ(a.pyramid.inverse_scales, b.pyramid.inverse_scales);
  EXPECT_EQ(a.pyramid.sigma2, b.pyramid.sigma2);
  EXPECT_EQ(a.pyramid.inverse_sigma2, b.pyramid.inverse_sigma2);
  ASSERT_EQ(a.keypoints.size(), b.keypoints.size());
  for (std::size_t i = 0; i < a.keypoints.size(); ++i) {
    const cv::KeyPoint& p = a.keypoints[i];
    const cv::KeyPoint& q = b.keypoints[i];
    EXPECT_EQ(Bits(p.pt.x), Bits(q.pt.x));
    EXPECT_EQ(Bits(p.pt.y), Bits(q.pt.y));
    EXPECT_EQ(Bits(p.size), Bits(q.size));
    EXPECT_EQ(Bits(p.angle), Bits(q.angle));
    EXPECT_EQ(Bits(p.response), Bits(q.response));
    EXPECT_EQ(p.octave, q.octave);
    EXPECT_EQ(p.class_id, q.class_id);
  }
  ASSERT_EQ(a.descriptors.rows, b.descriptors.rows);
  ASSERT_EQ(a.descriptors.type(), b.descriptors.type());
  for (int row = 0; row < a.descriptors.rows; ++row) {
    EXPECT_EQ(std::memcmp(a.Descriptor(row), b.Descriptor(row), kOrbDescriptorBytes), 0);
  }
  EXPECT_EQ(a.undistorted, b.undistorted);
}

void ExpectKeyframesEqual(const Keyframe& a, const Keyframe& b) {
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.frame_id, b.frame_id);
  EXPECT_EQ(Bits(a.timestamp_s), Bits(b.timestamp_s));
  ExpectCamerasEqual(a.camera, b.camera);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(Bits(a.cam_from_world.rotation.coeffs()[i]),
              Bits(b.cam_from_world.rotation.coeffs()[i]));
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(Bits(a.cam_from_world.translation[i]), Bits(b.cam_from_world.translation[i]));
  }
  ExpectFeaturesEqual(a.features, b.features);
  EXPECT_EQ(a.map_point_ids, b.map_point_ids);
  ASSERT_EQ(a.markers.size(), b.markers.size());
  for (std::size_t m = 0; m < a.markers.size(); ++m) {
    EXPECT_EQ(a.markers[m].marker_id, b.markers[m].marker_id);
    EXPECT_EQ(a.markers[m].corners_px, b.markers[m].corners_px);
  }
}

void ExpectPointsEqual(const MapPoint& a, const MapPoint& b) {
  EXPECT_EQ(a.id, b.id);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(Bits(a.p_in_world[i]), Bits(b.p_in_world[i]));
    EXPECT_EQ(Bits(a.normal[i]), Bits(b.normal[i]));
  }
  EXPECT_EQ(a.descriptor, b.descriptor);
  EXPECT_EQ(a.observations, b.observations);
  EXPECT_EQ(a.reference_keyframe, b.reference_keyframe);
  EXPECT_EQ(Bits(a.min_distance), Bits(b.min_distance));
  EXPECT_EQ(Bits(a.max_distance), Bits(b.max_distance));
  EXPECT_EQ(a.num_visible, b.num_visible);
  EXPECT_EQ(a.num_found, b.num_found);
}

void ExpectMapsEqual(const MapData& a, const MapData& b) {
  EXPECT_EQ(a.FirstKeyframe(), b.FirstKeyframe());
  EXPECT_EQ(a.LastKeyframe(), b.LastKeyframe());
  ASSERT_EQ(a.NumKeyframes(), b.NumKeyframes());
  ASSERT_EQ(a.NumMapPoints(), b.NumMapPoints());
  for (const auto& [id, keyframe] : a.keyframes()) {
    const Keyframe* other = b.FindKeyframe(id);
    ASSERT_NE(other, nullptr) << "keyframe " << id.value;
    ExpectKeyframesEqual(keyframe, *other);
    EXPECT_EQ(a.covisibility().Neighbours(id), b.covisibility().Neighbours(id));
    EXPECT_EQ(a.covisibility().Parent(id), b.covisibility().Parent(id));
    EXPECT_EQ(a.covisibility().Children(id), b.covisibility().Children(id));
  }
  for (const auto& [id, point] : a.map_points()) {
    const MapPoint* other = b.FindMapPoint(id);
    ASSERT_NE(other, nullptr) << "point " << id.value;
    ExpectPointsEqual(point, *other);
  }
}

std::string ErrorOf(std::string_view bytes) {
  try {
    DeserializeMap(bytes, "test.map");
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "test.map");
    return error.message();
  }
  return "";
}

void PutLittleEndian64(std::string& bytes, std::size_t offset, std::uint64_t value) {
  for (int i = 0; i < 8; ++i) bytes[offset + i] = static_cast<char>(value >> (8 * i));
}

// Replaces the trailer with the checksum of the (modified) content.
std::string Resign(std::string bytes) {
  PutLittleEndian64(bytes, bytes.size() - 8,
                    Fnv1a64(std::string_view(bytes).substr(0, bytes.size() - 8)));
  return bytes;
}

TEST(MapFileTest, Fnv1aMatchesReferenceValues) {
  // Published FNV-1a 64-bit test vectors.
  EXPECT_EQ(Fnv1a64(""), 0xcbf29ce484222325ULL);
  EXPECT_EQ(Fnv1a64("a"), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(Fnv1a64("foobar"), 0x85944171f73967e8ULL);
}

TEST(MapFileTest, RoundTripKeepsEveryField) {
  const MapData original = BuildTestMap(9, 60, 150, 1);
  ASSERT_GT(original.NumMapPoints(), 100u);
  int with_reference = 0;
  for (const auto& [id, point] : original.map_points()) {
    with_reference += point.reference_keyframe.IsValid() ? 1 : 0;
  }
  ASSERT_GT(with_reference, 0);
  const std::string bytes = SerializeMap(original);
  const MapData loaded = DeserializeMap(bytes, "test.map");
  EXPECT_EQ(loaded.CheckInvariants(), "");
  ExpectMapsEqual(original, loaded);
  // The hand-set parent survives (the tree is stored, not rebuilt from covisibility).
  EXPECT_EQ(loaded.covisibility().Parent(loaded.LastKeyframe()), loaded.FirstKeyframe());
  // Saving the loaded map gives the same bytes.
  EXPECT_TRUE(SerializeMap(loaded) == bytes);
}

TEST(MapFileTest, LoadedMapHandsOutFreshIds) {
  MapData loaded = DeserializeMap(SerializeMap(BuildTestMap(5, 30, 80, 2)), "test.map");
  const MapPointId largest_point = loaded.map_points().rbegin()->first;
  const KeyframeId largest_keyframe = loaded.keyframes().rbegin()->first;
  EXPECT_GT(loaded.AddMapPoint(MapPoint()), largest_point);
  Keyframe keyframe;
  EXPECT_GT(loaded.AddKeyframe(keyframe), largest_keyframe);
  EXPECT_EQ(loaded.CheckInvariants(), "");
}

TEST(MapFileTest, EmptyMapRoundTrips) {
  const MapData loaded = DeserializeMap(SerializeMap(MapData()), "test.map");
  EXPECT_EQ(loaded.NumKeyframes(), 0u);
  EXPECT_EQ(loaded.NumMapPoints(), 0u);
}

TEST(MapFileTest, SaveAndLoadFilesAndSharedMap) {
  const ScratchFolder scratch("map_file_test");
  const fs::path& dir = scratch.path();
  const MapData original = BuildTestMap(6, 40, 100, 3);
  SaveMapFile(original, dir / "a.map");
  SaveMapFile(original, dir / "a.map");  // replaces the file
  ExpectMapsEqual(original, LoadMapFile(dir / "a.map"));
  Map map;
  LoadMapFile(dir / "a.map", map);
  EXPECT_EQ(map.NumKeyframes(), original.NumKeyframes());
  SaveMapFile(map, dir / "b.map");
  EXPECT_TRUE(ReadTextFile(dir / "b.map") == ReadTextFile(dir / "a.map"));
  // No temporary file is left beside the outputs.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 2);
  // A failed load leaves the map untouched.
  WriteTextFileAtomically(dir / "bad.map", "not a map");
  EXPECT_THROW(LoadMapFile(dir / "bad.map", map), InputError);
  EXPECT_EQ(map.NumKeyframes(), original.NumKeyframes());
  EXPECT_THROW(SaveMapFile(original, dir / "missing_folder" / "c.map"), InputError);
}

TEST(MapFileTest, MissingFileNamesIt) {
  const ScratchFolder scratch("map_file_test");
  const fs::path path = scratch.path() / "nothing.map";
  try {
    LoadMapFile(path);
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), path.string());
    EXPECT_NE(error.message().find("does not exist"), std::string::npos) << error.message();
  }
}

TEST(MapFileTest, WrongMagicIsNotAMap) {
  EXPECT_NE(ErrorOf("P6\n640 480\n255\n").find("not an arucoslam map"), std::string::npos);
  std::string bytes = SerializeMap(BuildTestMap(3, 20, 30, 4));
  bytes[0] = 'X';
  EXPECT_NE(ErrorOf(bytes).find("not an arucoslam map"), std::string::npos) << ErrorOf(bytes);
}

TEST(MapFileTest, OtherVersionIsNamed) {
  std::string bytes = SerializeMap(BuildTestMap(3, 20, 30, 5));
  ASSERT_EQ(bytes[20], 3);  // version field (u32 little-endian after magic and byte order)
  bytes[20] = 4;
  EXPECT_EQ(ErrorOf(bytes), "map format version 4, this build reads 2 to 3");
  // A file of version 1 (no world-alignment flags) is refused the same way.
  bytes[20] = 1;
  EXPECT_EQ(ErrorOf(bytes), "map format version 1, this build reads 2 to 3");
}

// The bytes version 2 wrote for the same map: cameras with 5 distortion doubles instead of 14
// (the map's cameras must not use the other 9).
std::string AsVersion2(const std::string& version3) {
  constexpr std::size_t kCamerasAt = 32 + 8 + 4;  // header, META section, CAMS tag
  constexpr std::size_t kPrefix = 4 + 4 + 32 + 1 + 5 * 8, kDropped = 9 * 8, kSuffix = 8;
  EXPECT_EQ(version3.substr(kCamerasAt - 4, 4), "CAMS");
  std::uint32_t count = 0;
  std::memcpy(&count, version3.data() + kCamerasAt, 4);
  std::string bytes = version3.substr(0, kCamerasAt + 4);
  std::size_t at = kCamerasAt + 4;
  for (std::uint32_t i = 0; i < count; ++i) {
    EXPECT_EQ(version3.substr(at + kPrefix, kDropped), std::string(kDropped, '\0'));
    bytes += version3.substr(at, kPrefix) + version3.substr(at + kPrefix + kDropped, kSuffix);
    at += kPrefix + kDropped + kSuffix;
  }
  bytes += version3.substr(at);
  bytes[20] = 2;
  PutLittleEndian64(bytes, 24, bytes.size() - 32 - 8);
  return Resign(bytes);
}

TEST(MapFileTest, Version2FilesStillLoad) {
  const MapData original = BuildTestMap(5, 30, 60, 12);
  const std::string version2 = AsVersion2(SerializeMap(original));
  ASSERT_LT(version2.size(), SerializeMap(original).size());
  const MapData loaded = DeserializeMap(version2, "old.map");
  ExpectMapsEqual(original, loaded);
  // Saving writes the current version, which loads back equal.
  ExpectMapsEqual(original, DeserializeMap(SerializeMap(loaded), "new.map"));
}

TEST(MapFileTest, EveryDistortionModelRoundTrips) {
  MapData original;
  std::mt19937 random(13);
  for (const DistortionModel model :
       {DistortionModel::kNone, DistortionModel::kRadTan, DistortionModel::kEquidistant,
        DistortionModel::kRational, DistortionModel::kThinPrism, DistortionModel::kTilted}) {
    CameraModel camera = TestCamera(model);
    camera.distortion = {};
    for (int i = 0; i < NumDistortionCoefficients(model); ++i)
      camera.distortion[i] = 0.01 * (i + 1);
    ASSERT_TRUE(camera.Check()) << DistortionModelName(model);
    original.AddKeyframe(RandomKeyframe(5, camera, random));
  }
  const MapData loaded = DeserializeMap(SerializeMap(original), "test.map");
  ExpectMapsEqual(original, loaded);
}

TEST(MapFileTest, WorldAlignmentFlagRoundTrips) {
  const MapData original = BuildTestMap(3, 20, 30, 10);
  for (const bool aligned : {false, true}) {
    MapFileInfo written;
    written.world_aligned = aligned;
    const std::string bytes = SerializeMap(original, written);
    MapFileInfo read;
    read.world_aligned = !aligned;
    ExpectMapsEqual(original, DeserializeMap(bytes, "test.map", &read));
    EXPECT_EQ(read.world_aligned, aligned);
  }
  // Unknown flag bits are corruption, not silently ignored.
  std::string bytes = SerializeMap(original);
  ASSERT_EQ(bytes.substr(32, 4), "META");
  bytes[36] = 4;
  EXPECT_NE(ErrorOf(Resign(bytes)).find("unknown map flags 0x4"), std::string::npos)
      << ErrorOf(Resign(bytes));
}

TEST(MapFileTest, TruncationAtAnyOffsetIsDetected) {
  const std::string bytes = SerializeMap(BuildTestMap(4, 30, 60, 6));
  for (const std::size_t size :
       {std::size_t{0}, std::size_t{5}, std::size_t{16}, std::size_t{31}, std::size_t{32},
        std::size_t{33}, bytes.size() / 3, bytes.size() / 2, bytes.size() - 9, bytes.size() - 1}) {
    const std::string message = ErrorOf(std::string_view(bytes).substr(0, size));
    EXPECT_NE(message.find(fmt::format("ends after {} bytes", size)), std::string::npos)
        << "size " << size << ": " << message;
  }
  EXPECT_NE(ErrorOf(bytes + "x").find("trailing"), std::string::npos);
}

TEST(MapFileTest, EveryFlippedByteIsDetected) {
  const std::string bytes = SerializeMap(BuildTestMap(3, 8, 12, 7));
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::string corrupted = bytes;
    corrupted[i] = static_cast<char>(corrupted[i] ^ 0x10);
    EXPECT_NE(ErrorOf(corrupted), "") << "byte " << i << " of " << bytes.size();
  }
  std::string corrupted = bytes;
  corrupted[bytes.size() / 2] ^= 1;
  EXPECT_NE(ErrorOf(corrupted).find("checksum mismatch"), std::string::npos);
}

TEST(MapFileTest, CorruptContentWithValidChecksumIsAnInputError) {
  // A writer bug or a crafted file: every single-byte change, re-signed, either loads a map
  // that keeps the invariants or fails with InputError (never another exception or a crash).
  const std::string bytes = SerializeMap(BuildTestMap(3, 8, 12, 8));
  int rejected = 0;
  for (std::size_t i = 32; i + 8 < bytes.size(); ++i) {
    std::string corrupted = bytes;
    corrupted[i] = static_cast<char>(corrupted[i] ^ 0x41);
    corrupted = Resign(corrupted);
    try {
      EXPECT_EQ(DeserializeMap(corrupted, "test.map").CheckInvariants(), "");
    } catch (const InputError&) {
      ++rejected;
    }
  }
  EXPECT_GT(rejected, 0);
}

TEST(MapFileTest, InconsistentObservationsAreRejected) {
  MapData data = BuildTestMap(3, 8, 12, 9);
  std::string bytes = SerializeMap(data);
  // Point 0's first observation: keypoint index 0 of keyframe 0. Find the stored
  // (keyframe id 0, index 0) pair right after point 0's observation count and change the
  // index to a keypoint that observes nothing.
  const MapPoint& point = data.map_points().begin()->second;
  ASSERT_EQ(point.observations.begin()->second, 0);
  std::string pattern(16, '\0');  // u32 count, u64 keyframe 0, i32 index 0
  pattern[0] = static_cast<char>(point.observations.size());
  const std::size_t at = bytes.find(pattern, bytes.find("MPTS"));
  ASSERT_NE(at, std::string::npos);
  bytes[at + 4 + 8] = 1;
  EXPECT_NE(ErrorOf(Resign(bytes)).find("inconsistent map file"), std::string::npos)
      << ErrorOf(Resign(bytes));
}

}  // namespace
}  // namespace arucoslam
