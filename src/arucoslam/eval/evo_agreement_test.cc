// Reproduces evo v1.36.5's numbers on its own test data (../shared/data/evo_testdata):
// every case of expected_metrics_evo_v1.36.5.json to a relative 1e-6.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>

#include "arucoslam/eval/alignment.h"
#include "arucoslam/eval/association.h"
#include "arucoslam/eval/pose_error.h"
#include "arucoslam/eval/statistics.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

const fs::path kEvoData = fs::path(ARUCOSLAM_TEST_DATA_DIR) / "evo_testdata";

struct CaseFiles {
  std::string gt;
  std::string est;
  bool timestamped;
};

const std::map<std::string, CaseFiles>& Cases() {
  static const std::map<std::string, CaseFiles> cases = {
      {"KITTI_00_ORB", {"KITTI_00_gt.txt", "KITTI_00_ORB.txt", false}},
      {"KITTI_00_SPTAM", {"KITTI_00_gt.txt", "KITTI_00_SPTAM.txt", false}},
      {"fr1_xyz_rgbdslam", {"freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-rgbdslam.txt", true}},
      {"fr1_xyz_ORB_kf_mono",
       {"freiburg1_xyz-groundtruth.txt", "freiburg1_xyz-ORB_kf_mono.txt", true}},
      {"fr2_desk_ORB", {"fr2_desk_groundtruth.txt", "fr2_desk_ORB.txt", true}},
      {"fr2_desk_ORB_kf_mono", {"fr2_desk_groundtruth.txt", "fr2_desk_ORB_kf_mono.txt", true}},
      {"V102", {"V102_groundtruth.csv", "V102.txt", true}},
  };
  return cases;
}

AssociatedTrajectories LoadPairs(const CaseFiles& files) {
  if (!files.timestamped) {
    // KITTI without time: evo compares pose i with pose i.
    return AssociateByIndex(ReadKittiTrajectory(kEvoData / files.gt),
                            ReadKittiTrajectory(kEvoData / files.est));
  }
  return AssociateByTime(ReadTrajectory(kEvoData / files.gt), ReadTrajectory(kEvoData / files.est),
                         AssociationOptions{0.01});
}

PoseRelation RelationOf(const std::string& name) {
  if (name == "translation part") return PoseRelation::kTranslation;
  if (name == "rotation angle in degrees") return PoseRelation::kRotationAngleDeg;
  if (name == "full transformation") return PoseRelation::kFullTransformation;
  ADD_FAILURE() << "unknown relation " << name;
  return PoseRelation::kTranslation;
}

double worst_relative_difference = 0.0;

void ExpectRelativelyNear(double actual, double expected, const std::string& what) {
  const double bound = 1e-6 * std::abs(expected);
  worst_relative_difference =
      std::max(worst_relative_difference, std::abs(actual - expected) / std::abs(expected));
  EXPECT_NEAR(actual, expected, bound) << what;
}

TEST(EvoAgreement, EveryExpectedMetric) {
  const fs::path expected_path = kEvoData / "expected_metrics_evo_v1.36.5.json";
  if (!fs::is_regular_file(expected_path)) {
    GTEST_SKIP() << "missing test data folder " << kEvoData;
  }
  const nlohmann::json expected = nlohmann::json::parse(ReadTextFile(expected_path));
  ASSERT_EQ(expected.size(), 30u);
  std::map<std::string, AssociatedTrajectories> loaded;
  for (const nlohmann::json& entry : expected) {
    const std::string name = entry["case"];
    const std::string what =
        name + " " + entry["metric"].get<std::string>() + " " +
        entry["relation"].get<std::string>() + " align " + entry["align"].get<std::string>() +
        (entry.contains("delta")
             ? " delta " + entry["delta"].dump() + entry["delta_unit"].get<std::string>()
             : "");
    SCOPED_TRACE(what);
    ASSERT_TRUE(Cases().count(name)) << name;
    if (!loaded.count(name)) loaded.emplace(name, LoadPairs(Cases().at(name)));
    const AssociatedTrajectories& pairs = loaded.at(name);

    AlignmentOptions alignment;
    alignment.mode = *ParseAlignmentMode(entry["align"].get<std::string>());
    const std::optional<AlignmentResult> fit = ComputeAlignment(pairs, alignment);
    ASSERT_TRUE(fit.has_value());
    const Trajectory est = ApplyAlignment(fit->gt_from_est, pairs.est);
    const PoseRelation relation = RelationOf(entry["relation"]);

    std::vector<double> errors;
    if (entry["metric"] == "APE") {
      errors = AbsolutePoseErrors(pairs.gt, est, relation);
    } else {
      RelativeErrorOptions options;
      options.delta = entry["delta"].get<double>();
      options.unit = entry["delta_unit"] == "m" ? DeltaUnit::kMeters : DeltaUnit::kFrames;
      options.all_pairs = entry["all_pairs"].get<bool>();
      errors = RelativePoseErrors(pairs.gt, est, RelativeIndexPairs(est, options), relation);
    }
    const ErrorStatistics stats = ComputeErrorStatistics(errors);
    EXPECT_EQ(stats.count, entry["n_pairs"].get<std::size_t>());
    for (const auto& [key, value] :
         std::vector<std::pair<std::string, double>>{{"rmse", stats.rmse},
                                                     {"mean", stats.mean},
                                                     {"median", stats.median},
                                                     {"std", stats.std},
                                                     {"max", stats.max},
                                                     {"sse", stats.sse}}) {
      ExpectRelativelyNear(value, entry[key].get<double>(), key);
    }
    // The minimum of an unaligned KITTI run is the first pose (both start at the identity):
    // a few 1e-9 in evo, rounding noise of the file's 7 digits, so only an absolute check.
    EXPECT_NEAR(stats.min, entry["min"].get<double>(),
                std::max(1e-6 * std::abs(entry["min"].get<double>()), 1e-12))
        << "min";
  }
  std::printf("largest relative difference to evo: %.3g\n", worst_relative_difference);
}

}  // namespace
}  // namespace arucoslam
