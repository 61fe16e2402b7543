#pragma once
/// \file frame_drop_counter.h
/// Counts camera frames lost before the tracker (dropped by the subscriber queue, the network
/// or the driver) from gaps in the images' header.seq, or, when the publisher leaves seq
/// constant (roscpp does not fill it), from gaps in the stamps.

#include <cstdint>
#include <deque>

namespace klt_contour_tracker {

/// Fed every image that arrives, in arrival order; returns how many frames are missing
/// right before it.
/// - seq: once two consecutive images had different seq values, a step of k > 1 counts k - 1.
/// - stamps otherwise: the frame period is the median of the last 15 stamp steps; a step of
///   dt > 1.5 periods counts round(dt / period) - 1.
/// A step backwards (a looping bag, a restarted driver) or a jump of more than kMaxGap frames is
/// a discontinuity: nothing is counted and the period estimate starts over.
class FrameDropCounter {
 public:
  /// Gaps larger than this many frames are treated as a restart, not as drops.
  static constexpr std::uint64_t kMaxGap = 10000;

  /// Frames missing right before the image with this seq and stamp (seconds).
  std::uint64_t update(std::uint32_t seq, double stamp_s);
  /// Sum of all update() results.
  std::uint64_t total() const { return total_; }
  /// Forgets the history (the next image starts a new stream).
  void reset();

 private:
  bool have_previous_ = false;
  bool seq_informative_ = false;
  std::uint32_t previous_seq_ = 0;
  double previous_stamp_s_ = 0.0;
  std::deque<double> steps_s_;
  std::uint64_t total_ = 0;
};

}  // namespace klt_contour_tracker
