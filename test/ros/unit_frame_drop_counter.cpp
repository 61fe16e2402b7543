// FrameDropCounter: frames lost before the tracker from header.seq gaps, or stamp gaps when seq
// is constant (issue 10 item 4).
#include <gtest/gtest.h>

#include "klt_contour_tracker/ros/frame_drop_counter.h"

namespace {

using klt_contour_tracker::FrameDropCounter;

TEST(FrameDropCounter, CountsSeqGaps) {
  FrameDropCounter counter;
  EXPECT_EQ(counter.update(10, 1.0), 0u);
  EXPECT_EQ(counter.update(11, 1.1), 0u);
  EXPECT_EQ(counter.update(14, 1.4), 2u);  // 12 and 13 lost
  EXPECT_EQ(counter.update(15, 1.5), 0u);
  EXPECT_EQ(counter.total(), 2u);
  // A step back (looping bag) and a huge jump (restarted driver) are not drops.
  EXPECT_EQ(counter.update(3, 0.3), 0u);
  EXPECT_EQ(counter.update(4, 0.4), 0u);
  EXPECT_EQ(counter.update(4000000, 0.5), 0u);
  EXPECT_EQ(counter.total(), 2u);
}

TEST(FrameDropCounter, CountsStampGapsWhenSeqIsConstant) {
  FrameDropCounter counter;
  double t = 100.0;
  std::uint64_t dropped = 0;
  for (int i = 0; i < 10; ++i, t += 1.0 / 30) dropped += counter.update(0, t);
  EXPECT_EQ(dropped, 0u);
  t += 3.0 / 30;  // three frames missing
  EXPECT_EQ(counter.update(0, t), 3u);
  t += 1.0 / 30;
  EXPECT_EQ(counter.update(0, t), 0u);
  // Jitter of +-30 % is not a drop.
  t += 1.3 / 30;
  EXPECT_EQ(counter.update(0, t), 0u);
  t += 0.7 / 30;
  EXPECT_EQ(counter.update(0, t), 0u);
  // Stamps going back: a new stream, nothing counted.
  EXPECT_EQ(counter.update(0, 1.0), 0u);
  EXPECT_EQ(counter.total(), 3u);
}

TEST(FrameDropCounter, FarFutureStampIsADiscontinuityNotADrop) {
  FrameDropCounter counter;
  for (int i = 0; i < 10; ++i) counter.update(0, 100.0 + i * 0.1);
  EXPECT_EQ(counter.update(0, 4294967295.999999999), 0u);
  EXPECT_EQ(counter.total(), 0u);
}

}  // namespace
