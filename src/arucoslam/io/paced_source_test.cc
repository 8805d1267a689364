#include "arucoslam/io/paced_source.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

#include "arucoslam/io/recording_test_util.h"

namespace arucoslam {
namespace {

using testing_util::Recording;

using Clock = std::chrono::steady_clock;

TEST(PacedSourceTest, AConsumerThatKeepsUpGetsEveryFrameNoSoonerThanRecorded) {
  const Clock::time_point start = Clock::now();
  // 50 ms between frames: a consumer stalled by a loaded machine for less than two intervals
  // (the queue holds two frames) still keeps up.
  PacedSource source(std::make_unique<Recording>(20, 0.05));
  EXPECT_TRUE(source.live());
  EXPECT_EQ(source.size(), std::optional<std::size_t>(20));
  EXPECT_EQ(source.camera().width, 8);
  std::vector<double> timestamps;
  while (std::optional<SourceFrame> frame = source.Next()) {
    EXPECT_EQ(frame->index, timestamps.size());
    EXPECT_EQ(frame->image.at<std::uint8_t>(0, 0), timestamps.size());  // the recording's own
    // The last frame is due 0.95 s after the first was handed over.
    if (frame->index == 19) {
      EXPECT_GE(std::chrono::duration<double>(Clock::now() - start).count(), 0.95);
    }
    timestamps.push_back(frame->timestamp_s);
  }
  EXPECT_EQ(source.frames_dropped(), 0u);
  ASSERT_EQ(timestamps.size(), 20u);
  EXPECT_DOUBLE_EQ(timestamps.front(), 100.0);
  EXPECT_DOUBLE_EQ(timestamps.back(), 100.95);
}

TEST(PacedSourceTest, FasterReplayTakesLessTime) {
  PacedSourceOptions options;
  options.speed = 4.0;
  options.queue_capacity = 100;  // nothing dropped: the replay's own time is what is measured
  const Clock::time_point start = Clock::now();
  PacedSource source(std::make_unique<Recording>(41, 0.01), options);
  std::size_t handed = 0;
  while (source.Next()) ++handed;
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - start).count();
  EXPECT_EQ(handed, 41u);
  EXPECT_GE(elapsed_s, 0.1);  // 0.4 s of recording at 4x
}

TEST(PacedSourceTest, ASlowConsumerLosesFramesAndEveryFrameIsCounted) {
  PacedSource source(std::make_unique<Recording>(40, 0.005));  // 0.2 s of recording
  std::size_t handed = 0;
  double last_timestamp_s = 0.0;
  while (std::optional<SourceFrame> frame = source.Next()) {
    EXPECT_GT(frame->timestamp_s, last_timestamp_s);
    last_timestamp_s = frame->timestamp_s;
    ++handed;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // 10 frame intervals
  }
  EXPECT_EQ(handed + source.frames_dropped(), 40u);
  EXPECT_GE(source.frames_dropped(), 20u);
}

TEST(PacedSourceTest, StopFlagEndsTheReplay) {
  std::atomic<bool> stop{false};
  PacedSourceOptions options;
  options.stop = &stop;
  PacedSource source(std::make_unique<Recording>(1000, 0.01), options);  // 10 s of recording
  ASSERT_TRUE(source.Next());
  stop = true;
  const Clock::time_point stopped = Clock::now();
  std::size_t handed = 1;
  while (source.Next()) ++handed;
  EXPECT_LT(handed, 1000u);
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - stopped).count(), 5.0);
}

TEST(PacedSourceTest, AnUnreadableFrameIsThrownAfterTheFramesBeforeIt) {
  PacedSource source(std::make_unique<Recording>(10, 0.02, 4));
  // Every frame before the unreadable one is handed over (or, on a machine too loaded to keep
  // up, counted as dropped) before the error; none after it.
  std::size_t handed = 0;
  EXPECT_THROW(
      {
        while (std::optional<SourceFrame> frame = source.Next()) {
          EXPECT_LT(frame->image.at<std::uint8_t>(0, 0), 4);
          ++handed;
        }
      },
      InputError);
  EXPECT_EQ(handed + source.frames_dropped(), 4u);
}

TEST(PacedSourceTest, DestructorStopsAReplayNobodyReads) {
  const Clock::time_point start = Clock::now();
  { PacedSource source(std::make_unique<Recording>(1000, 0.01)); }
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - start).count(), 5.0);
}

TEST(PacedSourceTest, BadOptionsAreRefused) {
  PacedSourceOptions options;
  options.speed = 0.0;
  std::string why;
  EXPECT_FALSE(options.Check(&why));
  EXPECT_NE(why.find("speed"), std::string::npos) << why;
  EXPECT_THROW(PacedSource(std::make_unique<Recording>(3, 0.01), options), std::invalid_argument);
  options = {};
  options.queue_capacity = 0;
  EXPECT_FALSE(options.Check());
}

}  // namespace
}  // namespace arucoslam
