// The run's config file: SystemOptions written as commented YAML and read back equal; one
// key changes one option; bad files fail with the file, key path and line; and every field
// of every options struct is visited (a field added without its VisitOptions line fails).
#include "arucoslam/io/config_file.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "arucoslam/pipeline/options_visit.h"
#include "arucoslam/pipeline/system.h"
#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream stream(text);
  for (std::string line; std::getline(stream, line);) lines.push_back(line);
  return lines;
}

SystemOptions Parse(const std::string& text, SystemOptions options = {}) {
  ParseSystemOptions(text, "test.yaml", options);
  return options;
}

// The message of the InputError that parsing `text` throws ("" when none).
std::string ParseError(const std::string& text) {
  SystemOptions options;
  try {
    ParseSystemOptions(text, "test.yaml", options);
  } catch (const InputError& error) {
    EXPECT_EQ(SystemOptionsYaml(options), SystemOptionsYaml(SystemOptions{}))
        << "options changed by a failed read";
    return error.what();
  }
  return "";
}

TEST(ConfigFileTest, WrittenOptionsReadBackEqual) {
  SystemOptions options;
  options.blocking = false;
  options.min_marker_init_parallax_deg = 0.1 + 0.2;  // 0.30000000000000004: written exactly
  options.initializer.seed = 4000000000u;
  options.detector.corner_refinement = CornerRefinement::kAprilTag;
  options.marker_mapping.ground_plane_prior = GroundPlanePriorOptions{.height_sigma_m = 0.02};
  options.mapper.bundle_adjustment.solver.function_tolerance = 1e-7;
  const std::string written = SystemOptionsYaml(options);
  const SystemOptions read = Parse(written);
  EXPECT_EQ(SystemOptionsYaml(read), written);
  EXPECT_FALSE(read.blocking);
  EXPECT_EQ(read.min_marker_init_parallax_deg, 0.1 + 0.2);
  EXPECT_EQ(read.initializer.seed, 4000000000u);
  EXPECT_EQ(read.detector.corner_refinement, CornerRefinement::kAprilTag);
  ASSERT_TRUE(read.marker_mapping.ground_plane_prior.has_value());
  EXPECT_EQ(read.marker_mapping.ground_plane_prior->height_sigma_m, 0.02);
  EXPECT_EQ(read.mapper.bundle_adjustment.solver.function_tolerance, 1e-7);
  // Enums by name; an unset optional section as null with its keys commented out.
  EXPECT_NE(written.find("  corner_refinement: apriltag  # "), std::string::npos);
  const std::string unset = SystemOptionsYaml(SystemOptions{});
  EXPECT_NE(unset.find("  ground_plane_prior: null  # "), std::string::npos);
  EXPECT_NE(unset.find("    # height_sigma_m: 0.01  # "), std::string::npos);
}

TEST(ConfigFileTest, EveryKeyHasAComment) {
  int keys = 0;
  for (const std::string& line : Lines(SystemOptionsYaml(SystemOptions{}))) {
    if (line.empty() || line.front() == '#') continue;
    ++keys;
    const std::size_t comment = line.find("  # ");
    ASSERT_NE(comment, std::string::npos) << line;
    EXPECT_GT(line.size(), comment + 4) << line;
  }
  EXPECT_GT(keys, 300);
}

TEST(ConfigFileTest, OneKeyChangesOneOption) {
  const SystemOptions read = Parse(
      "# a comment\n"
      "tracker:\n"
      "  motion_search:\n"
      "    base_radius_px: 12.5\n");
  EXPECT_EQ(read.tracker.motion_search.base_radius_px, 12.5);
  SystemOptions expected;
  expected.tracker.motion_search.base_radius_px = 12.5;
  EXPECT_EQ(SystemOptionsYaml(read), SystemOptionsYaml(expected));

  // Over other starting values: keys left out keep them.
  SystemOptions start;
  start.extractor.min_fast_threshold = 6;
  const SystemOptions over = Parse("extractor: {num_features: 1500}\nblocking: false\n", start);
  EXPECT_EQ(over.extractor.num_features, 1500);
  EXPECT_EQ(over.extractor.min_fast_threshold, 6);
  EXPECT_FALSE(over.blocking);
  // Integers are numbers too; an empty file changes nothing.
  EXPECT_EQ(
      Parse("world_anchoring: {max_alignment_scale: 80}\n").world_anchoring.max_alignment_scale,
      80.0);
  EXPECT_EQ(SystemOptionsYaml(Parse("# nothing\n", start)), SystemOptionsYaml(start));
}

TEST(ConfigFileTest, OptionalSectionsAreSetPartlyOrUnset) {
  const SystemOptions set =
      Parse("marker_mapping:\n  ground_plane_prior:\n    tilt_sigma_rad: 0.01\n");
  ASSERT_TRUE(set.marker_mapping.ground_plane_prior.has_value());
  EXPECT_EQ(set.marker_mapping.ground_plane_prior->tilt_sigma_rad, 0.01);
  EXPECT_EQ(set.marker_mapping.ground_plane_prior->height_sigma_m,
            GroundPlanePriorOptions{}.height_sigma_m);
  const SystemOptions unset = Parse("marker_mapping: {ground_plane_prior: null}\n", set);
  EXPECT_FALSE(unset.marker_mapping.ground_plane_prior.has_value());
}

TEST(ConfigFileTest, BadFilesNameTheKeyAndLine) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"extractor:\n  num_features: [1\n", "test.yaml: not valid YAML: line 3"},
      {"extractor:\n  num_featurs: 1500\n",
       "test.yaml: extractor.num_featurs (line 2): unknown key (did you mean num_features?)"},
      {"trackr:\n  min_motion_matches: 5\n", "test.yaml: trackr (line 1): unknown key"},
      {"vocabulary: x.bin\n", "vocabulary (line 1): unknown key"},
      {"extractor:\n  num_features: many\n",
       "test.yaml: extractor.num_features (line 2): expected an integer, found 'many'"},
      {"blocking: 1\n", "blocking (line 1): expected true or false, found '1'"},
      {"initializer: {seed: -1}\n", "initializer.seed (line 1): expected an integer from 0 to"},
      {"world_anchoring:\n  alignment:\n    outlier_threshold_m: nan\n",
       "world_anchoring.alignment.outlier_threshold_m (line 3): expected a number, found 'nan'"},
      {"detector:\n  corner_refinement: fancy\n",
       "detector.corner_refinement (line 2): expected one of none, subpix, contour, apriltag"},
      {"extractor: 3\n", "extractor (line 1): expected a section"},
      {"extractor:\n  rotation: {}\n", "extractor.rotation (line 2): unknown key"},
      {"- extractor\n", "test.yaml: line 1: expected a map of sections and keys"},
      {"extractor:\n  num_levels: 3\n  num_levels: 4\n",
       "extractor.num_levels (line 3): duplicate key"},
      {"extractor:\n  num_features: 1500\n  num_levels: 0\n",
       "test.yaml: extractor.num_levels (line 3): 0 is out of range or inconsistent with the "
       "other extractor options: extractor.num_levels must be in [1, 32], is 0"},
      {"mapper:\n  bundle_adjustment:\n    solver:\n      max_iterations: -2\n",
       "mapper.bundle_adjustment.solver.max_iterations (line 4): -2 is out of range or "
       "inconsistent with the other mapper.bundle_adjustment.solver options: "
       "mapper.bundle_adjustment.solver.max_iterations must be >= 1, is -2"},
      {"world_anchoring:\n  min_alignment_anchors: 8\n  max_realignment_anchors: 6\n",
       "test.yaml: world_anchoring (line 2): these values fail the world_anchoring options' "
       "check together: world_anchoring.min_alignment_anchors: 8 (line 2), "
       "world_anchoring.max_realignment_anchors: 6 (line 3); "
       "world_anchoring.max_realignment_anchors must be >= min_alignment_anchors (8), is 6"},
  };
  for (const auto& [text, expected] : cases) {
    const std::string message = ParseError(text);
    EXPECT_NE(message.find(expected), std::string::npos) << text << "\n -> " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

TEST(ConfigFileTest, MissingFileIsNamed) {
  SystemOptions options;
  const std::filesystem::path missing = std::filesystem::temp_directory_path() / "no_such.yaml";
  try {
    ReadSystemOptions(missing, options);
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), missing.string());
    EXPECT_NE(error.message().find("does not exist"), std::string::npos) << error.what();
  }
}

// ---- Every field visited: an options struct's member count (brace initialisation with one
// convertible-to-anything argument per member) against the keys its VisitOptions lists.

// A member type AnyField converts to: any but std::optional and other wrappers with a
// value_type, whose converting constructors would make the initialisation ambiguous (their
// own member count is not wanted anyway); strings are members like any other.
template <class T>
concept PlainMember = !requires {
  typename T::value_type;
}
|| requires(T t) { t.c_str(); };

struct AnyField {
  template <PlainMember T>
  operator T() const;  // never defined: used in requires-expressions only
};

template <class T, std::size_t... I>
constexpr bool BraceInitializable(std::index_sequence<I...>) {
  return requires { T{(static_cast<void>(I), AnyField{})...}; };
}

template <class T, std::size_t N = 0>
constexpr std::size_t MemberCount() {
  if constexpr (BraceInitializable<T>(std::make_index_sequence<N + 1>{})) {
    return MemberCount<T, N + 1>();
  } else {
    return N;
  }
}

struct KeyCounter {
  int keys = 0;
  void operator()(std::string_view, auto&, std::string_view) { ++keys; }
};

// Visits every options struct of the tree and compares its members with its keys.
struct FieldCountChecker {
  template <class T>
  void operator()(std::string_view key, T& value, std::string_view) {
    if constexpr (requires { value.has_value(); }) {
      typename T::value_type inner;
      (*this)(key, inner, "");
    } else if constexpr (requires { VisitOptions(value, *this); }) {
      Check(value, key);
    }
  }

  template <class Options>
  void Check(Options& options, std::string_view name) {
    KeyCounter counter;
    VisitOptions(options, counter);
    // Members that are not options, each named in a comment of its VisitOptions.
    int left_out = 0;
    if constexpr (std::is_same_v<Options, SystemOptions>) left_out = 2;    // marker_map, vocabulary
    if constexpr (std::is_same_v<Options, DetectorOptions>) left_out = 1;  // dictionary
    if constexpr (std::is_same_v<Options, BundleAdjustmentOptions>) left_out = 1;  // callback
    EXPECT_EQ(static_cast<int>(MemberCount<Options>()), counter.keys + left_out)
        << name << ": a field without its line in VisitOptions (options_visit.h)?";
    ++num_structs;
    VisitOptions(options, *this);
  }

  int num_structs = 0;
};

TEST(ConfigFileTest, EveryFieldOfEveryOptionsStructIsVisited) {
  SystemOptions options;
  FieldCountChecker checker;
  checker.Check(options, "SystemOptions");
  EXPECT_GT(checker.num_structs, 60);  // with repeats (rotation checks, solvers, ...)
}

}  // namespace
}  // namespace arucoslam
