#pragma once
/// \file region_cost.h
/// The region (colour) cue as a term of the coarse-to-fine objective (pose_cost.h), with the
/// colour model it learns at trusted poses (ours, beyond the paper; SRT3D's region modality).

#include <memory>
#include <opencv2/core.hpp>

#include "klt_contour_tracker/core/color_histograms.h"
#include "klt_contour_tracker/core/pose_cost.h"
#include "klt_contour_tracker/core/region_cue.h"
#include "klt_contour_tracker/core/renderer.h"

namespace kct {

/// RegionCue over the frame's colour image: lines on level l are stretched by 2^l (a coarse
/// level sees a 2^l times wider band around the outline), posteriors are read at full
/// resolution. Inactive until the colour model was learned, on grey frames and without an
/// outline.
class RegionCost : public PoseCost {
 public:
  /// `band_px` (>= 1): width of the bands along the silhouette the colours are learned from,
  /// px; `learning_rate` in (0, 1]: weight of a new frame in the histograms. Throws
  /// std::invalid_argument for bad values (RegionCue's and ColorHistograms' checks).
  RegionCost(std::shared_ptr<const ContourExtractor> extractor, const RegionCueSettings& settings,
             int band_px, double learning_rate);

  std::string name() const override { return "region"; }
  void begin_frame(const PoseCostFrame& frame) override;
  void linearize(const Pose& object_to_camera, int level) override;
  double evaluate(const Pose& object_to_camera, Vector6d* gradient,
                  Matrix6d* hessian) const override;
  bool active() const override { return frame_ok_ && cue_.line_count() > 0; }

  /// Learns the colours along the silhouette of the mesh rendered at `object_to_camera` (a
  /// pose the tracker trusts) in `bgr` (CV_8UC3, undistorted). Returns false when nothing was
  /// learned (grey frame, object too small or outside the image).
  bool learn(const cv::Mat& bgr, const Pose& object_to_camera, const PinholeCamera& camera);
  /// Same with the silhouette already rendered at that pose (CV_8UC1 of the frame's size,
  /// non-zero on the object; e.g. KeypointTracker::object_mask()).
  bool learn(const cv::Mat& bgr, const cv::Mat& mask);
  /// Forgets the colour model (e.g. a new track).
  void forget() { histograms_.clear(); }
  const ColorHistograms& histograms() const { return histograms_; }

 private:
  /// The mesh's mask (CV_8UC1, non-zero on the object) rendered at a pose.
  cv::Mat silhouette(const Pose& object_to_camera, const PinholeCamera& camera) const;

  RegionCue cue_;
  ColorHistograms histograms_;
  Renderer renderer_;
  int band_px_;
  double learning_rate_;
  const PoseCostFrame* frame_ = nullptr;
  bool frame_ok_ = false;
  double radius_m_ = 0.0;               ///< largest vertex distance from the bounding-box centre
  int lines_level_ = -1;                ///< level of the placed lines, -1 = none this frame
  Pose lines_pose_ = Pose::Identity();  ///< pose the lines were placed at
};

}  // namespace kct
