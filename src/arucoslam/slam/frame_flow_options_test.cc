#include "arucoslam/slam/frame_flow_options.h"

#include <gtest/gtest.h>

#include <string>

namespace arucoslam {
namespace {

TEST(FrameFlowOptions, DefaultsPass) {
  std::string why = "untouched";
  EXPECT_TRUE(FrameFlowOptions().Check(&why));
  EXPECT_EQ(why, "untouched");
  EXPECT_TRUE(FrameFlowOptions().Check());
}

TEST(FrameFlowOptions, CheckNamesTheField) {
  struct Case {
    const char* reason;
    void (*spoil)(FrameFlowOptions&);
  };
  const Case cases[] = {
      {"refine_min_inlier_fraction must be in (0, 1], is 0",
       [](FrameFlowOptions& o) { o.refine_min_inlier_fraction = 0.0; }},
      {"min_frames_between_anchor_keyframes must be >= 0, is -1",
       [](FrameFlowOptions& o) { o.min_frames_between_anchor_keyframes = -1; }},
      {"synchronous_young_map_keyframes must be >= 0, is -2",
       [](FrameFlowOptions& o) { o.synchronous_young_map_keyframes = -2; }},
      {"initialization.max_reference_gap_s must be > 0, is 0",
       [](FrameFlowOptions& o) { o.initialization.max_reference_gap_s = 0.0; }},
      {"map_session.new_map_after_lost_s must be > 0, is -1",
       [](FrameFlowOptions& o) { o.map_session.new_map_after_lost_s = -1.0; }},
      {"marker_mapping.min_locating_keyframes must be >= 0, is -3",
       [](FrameFlowOptions& o) { o.marker_mapping.min_locating_keyframes = -3; }},
      {"mapper.bundle_adjustment.solver.max_iterations must be >= 1, is 0",
       [](FrameFlowOptions& o) { o.mapper.bundle_adjustment.solver.max_iterations = 0; }},
  };
  for (const Case& c : cases) {
    FrameFlowOptions options;
    c.spoil(options);
    std::string why;
    EXPECT_FALSE(options.Check(&why)) << c.reason;
    EXPECT_EQ(why, c.reason);
    EXPECT_FALSE(options.Check());
  }
}

}  // namespace
}  // namespace arucoslam
