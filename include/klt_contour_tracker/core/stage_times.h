#pragma once
/// \file stage_times.h
/// Where one frame's time went, per stage of the pipeline (for the benchmark's stage table).

namespace kct {

/// Wall time per stage of one track() call, milliseconds. Stages that ran on another thread
/// (num_threads > 1: the refinement's image work overlaps KLT) count their own wall time, so
/// the sum may exceed TrackResult::frame_time_ms.
struct StageTimes {
  double klt_ms = 0.0;                ///< KLT tracking (illumination normalization included)
  double pnp_ms = 0.0;                ///< PnP + RANSAC
  double keypoint_detection_ms = 0.0; ///< keypoint re-detection (render, corners, anchoring)
  double image_ms = 0.0;              ///< refinement's image work (blur, gradients, pyramid)
  double contour_extraction_ms = 0.0; ///< Algorithm 1 and contour sampling
  double energy_ms = 0.0;             ///< objective evaluations (Eq. 5 and the other cues)
  double optimizer_ms = 0.0;          ///< the rest of the refinement (optimizer bookkeeping)
};

}  // namespace kct
