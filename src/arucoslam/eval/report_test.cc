#include "arucoslam/eval/report.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace arucoslam {
namespace {

Trajectory Line(double z_offset) {
  Trajectory t;
  for (int i = 0; i < 50; ++i) {
    t.Add(0.1 * i,
          Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.1 * i, 0.02 * i * i, z_offset)));
  }
  return t;
}

TEST(Report, TableJsonAndPlotsAgreeWithTheEvaluations) {
  const Trajectory gt = Line(0.0);
  EvaluationOptions options;
  options.relative = {RelativeErrorOptions{}, RelativeErrorOptions{1.0, DeltaUnit::kMeters}};
  std::vector<TrajectoryEvaluation> evaluations = {
      EvaluateTrajectory(gt, Line(0.03), "with markers", "a.txt", options),
      EvaluateTrajectory(gt, Line(0.25), "no markers", "b.txt", options)};
  evaluations[0].tracking = RunTrackingStats{1, 1};

  const std::string table = FormatEvaluationTable(evaluations);
  EXPECT_NE(table.find("with markers"), std::string::npos);
  EXPECT_NE(table.find("no markers"), std::string::npos);
  EXPECT_NE(table.find("APE translation rmse [m]"), std::string::npos);
  EXPECT_NE(table.find("0.0300"), std::string::npos);
  EXPECT_NE(table.find("0.2500"), std::string::npos);
  EXPECT_NE(table.find("RPE 1 m translation rmse [m]"), std::string::npos);
  EXPECT_NE(table.find("1 / 1"), std::string::npos);  // losses / relocalisations

  const nlohmann::json json =
      nlohmann::json::parse(FormatResultsJson(evaluations, {"a.txt", "b.txt"}, "gt.txt", options));
  EXPECT_EQ(json["format"], "arucoslam.eval/1");
  ASSERT_EQ(json["estimates"].size(), 2u);
  const nlohmann::json& b = json["estimates"][1];
  EXPECT_EQ(b["file"], "b.txt");
  EXPECT_EQ(b["ape"]["translation_m"]["rmse"].get<double>(), evaluations[1].ape_translation.rmse);
  EXPECT_NEAR(b["ape"]["translation_m"]["rmse"].get<double>(), 0.25, 1e-12);
  EXPECT_EQ(b["poses"]["pairs"], 50);
  EXPECT_EQ(b["rpe"].size(), 2u);
  EXPECT_EQ(b["rpe"][1]["delta_unit"], "m");
  EXPECT_NEAR(b["per_axis"]["mean_abs"][2].get<double>(), 0.25, 1e-12);
  EXPECT_FALSE(b.contains("tracking"));
  EXPECT_EQ(json["estimates"][0]["tracking"]["losses"], 1);

  const auto plots = MakeEvaluationPlots(gt, evaluations);
  ASSERT_EQ(plots.size(), 3u);
  EXPECT_EQ(plots[0].first, "trajectory_top_down.svg");
  for (const auto& [name, svg] : plots) {
    EXPECT_NE(svg.find("with markers"), std::string::npos) << name;
    EXPECT_NE(svg.find("no markers"), std::string::npos) << name;
    EXPECT_NE(svg.find("[m]"), std::string::npos) << name;  // axes carry units
  }
  EXPECT_NE(plots[0].second.find("ground truth"), std::string::npos);
}

}  // namespace
}  // namespace arucoslam
