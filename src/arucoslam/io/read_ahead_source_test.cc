#include "arucoslam/io/read_ahead_source.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "arucoslam/io/recording_test_util.h"

namespace arucoslam {
namespace {

using testing_util::Recording;

TEST(ReadAheadSourceTest, HandsOutTheRecordingsFramesInItsOrderThenEnds) {
  ReadAheadSource source(std::make_unique<Recording>(50, 0.1), ReadAheadOptions{3});
  EXPECT_FALSE(source.live());
  EXPECT_EQ(source.size(), std::optional<std::size_t>(50));
  EXPECT_EQ(source.camera().width, 8);
  EXPECT_EQ(source.layout(), "images");
  std::size_t count = 0;
  while (std::optional<SourceFrame> frame = source.Next()) {
    EXPECT_EQ(frame->index, count);
    EXPECT_DOUBLE_EQ(frame->timestamp_s, 100.0 + 0.1 * static_cast<double>(count));
    EXPECT_EQ(frame->image.at<std::uint8_t>(0, 0), count);  // the recording's own image
    ++count;
  }
  EXPECT_EQ(count, 50u);
  EXPECT_FALSE(source.Next().has_value());  // stays at the end
  EXPECT_EQ(source.frames_dropped(), 0u);
}

TEST(ReadAheadSourceTest, AnUnreadableFrameIsReportedInItsPlace) {
  ReadAheadSource source(std::make_unique<Recording>(10, 0.1, 6));
  for (std::size_t i = 0; i < 6; ++i) {
    const std::optional<SourceFrame> frame = source.Next();
    ASSERT_TRUE(frame.has_value());
    EXPECT_EQ(frame->index, i);
  }
  EXPECT_THROW(source.Next(), InputError);
  EXPECT_FALSE(source.Next().has_value());
}

TEST(ReadAheadSourceTest, AnUnreadableFrameNeverAskedForIsNotReported) {
  // The reader reaches frame 5 while the consumer stops after 2 (as `run --max-frames 2`).
  ReadAheadSource source(std::make_unique<Recording>(10, 0.1, 5), ReadAheadOptions{8});
  EXPECT_TRUE(source.Next().has_value());
  EXPECT_TRUE(source.Next().has_value());
}

TEST(ReadAheadSourceTest, DestroyedWithFramesLeftOrNeverReadItDoesNotHang) {
  {
    ReadAheadSource source(std::make_unique<Recording>(1000, 0.01), ReadAheadOptions{2});
    EXPECT_TRUE(source.Next().has_value());  // the reader then waits for room
  }
  { ReadAheadSource never_read(std::make_unique<Recording>(1000, 0.01)); }
}

TEST(ReadAheadSourceTest, RefusesAnEmptyQueue) {
  EXPECT_THROW(ReadAheadSource(std::make_unique<Recording>(3, 0.01), ReadAheadOptions{0}),
               std::invalid_argument);
}

}  // namespace
}  // namespace arucoslam
