#include "klt_contour_tracker/ros/frame_drop_counter.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace klt_contour_tracker {

void FrameDropCounter::reset() {
  have_previous_ = false;
  seq_informative_ = false;
  steps_s_.clear();
}

std::uint64_t FrameDropCounter::update(std::uint32_t seq, double stamp_s) {
  std::uint64_t dropped = 0;
  if (have_previous_) {
    if (seq != previous_seq_) seq_informative_ = true;
    const double dt = stamp_s - previous_stamp_s_;
    if (seq_informative_) {
      if (seq > previous_seq_ && seq - previous_seq_ <= kMaxGap)
        dropped = seq - previous_seq_ - 1;
      else
        steps_s_.clear();  // restart: also the stamps' period
    } else if (std::isfinite(dt) && dt > 0.0) {
      if (steps_s_.size() >= 3) {
        std::vector<double> sorted(steps_s_.begin(), steps_s_.end());
        std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
        const double period = sorted[sorted.size() / 2];
        const double frames = dt / period;
        if (frames > 1.5 && frames <= static_cast<double>(kMaxGap))
          dropped = static_cast<std::uint64_t>(std::lround(frames)) - 1;
        else if (frames > static_cast<double>(kMaxGap))
          steps_s_.clear();
      }
    } else {
      steps_s_.clear();  // stamps went backwards or stood still: a new stream
    }
    if (std::isfinite(dt) && dt > 0.0) {
      steps_s_.push_back(dt);
      if (steps_s_.size() > 15) steps_s_.pop_front();
    }
  }
  have_previous_ = true;
  previous_seq_ = seq;
  previous_stamp_s_ = stamp_s;
  total_ += dropped;
  return dropped;
}

}  // namespace klt_contour_tracker
