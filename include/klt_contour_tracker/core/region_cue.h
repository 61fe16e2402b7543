#pragma once
/// \file region_cue.h
/// Region (colour) cue of a pose (ours, beyond the paper): how well the object's silhouette
/// separates foreground-coloured from background-coloured pixels, measured along
/// correspondence lines across the projected contour as SRT3D does (Stoiber et al., "SRT3D: A
/// Sparse Region-Based 3D Object Tracking Approach for the Real World", IJCV 2022, Sec. 4),
/// with its analytic gradient and a Gauss-Newton-style Hessian with respect to a pose increment.
///
/// Complements the contour energy (Eq. 5): it prefers the pose whose outline has the object's
/// colours inside and the background's outside, so a contour lying on background texture next
/// to the object costs more however strong that texture's edges are. Where the background has
/// the object's colours every posterior is 0.5, the cue is flat and leaves the decision to the
/// edges and keypoints.

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/color_histograms.h"
#include "klt_contour_tracker/core/contour_extractor.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/pose_cost.h"

namespace kct {

/// Settings of the correspondence lines (lengths in full-resolution pixels at scale 1).
struct RegionCueSettings {
  int line_half_length_px = 12;  ///< L: pixels sampled on each side of the contour
  double line_spacing_px = 6.0;  ///< distance between lines along the contour, px
  double step_slope_px = 1.5;    ///< s_h: width of the smoothed step function, px
  double step_amplitude = 0.45;  ///< alpha_h in (0, 0.5): how sure the step is
};

/// Correspondence-line region cue.
///
/// linearize() places lines across the projected Contour edges (silhouette; sharp edges are
/// inside the object) every line_spacing_px * scale, each through a model point X_i on the
/// edge, along the outward unit normal n_i (away from the edge's front face), and reads
/// P_ij = P(foreground | colour) (ColorHistograms; 0.5 outside the image: no information) at
/// offsets s_j = (j + 0.5) scale, j = -L .. L-1. With the smoothed step
/// h_f(s) = 1/2 - alpha_h tanh(s / (2 s_h scale)) (probability that offset s lies on the
/// object), the likelihood that the outline crosses the line at offset d is
///   p_i(d) ~ prod_j [h_f(s_j - d) P_ij + (1 - h_f(s_j - d)) (1 - P_ij)]
/// over d = k scale, |k| < L (SRT3D Eq. 7-9); with a silhouette, only lines on the outer
/// outline, each cut where it meets another part of the object or leaves a thin one (see
/// linearize()). Its mean mu_i and variance sigma_i^2 (at least (scale / 2)^2) are held fixed
/// until the next linearize(). evaluate() projects X_i at the pose, takes its shift
/// delta_i = n_i . (pi(X_i) - c_i) along the line and returns
///   cost = (1 / N) sum_i 0.5 w_i (delta_i - mu_i)^2,  w_i = 1 / sigma_i^2 - 1 / sigma_u^2,
/// sigma_u^2 the variance of a uniform p_i (w_i >= 0: a line that tells nothing, all its
/// P = 1/2 or outside the image, weighs exactly 0; N counts every line, so poses pushing the
/// outline out of the image gain nothing). This Gaussian form is SRT3D's: its Gauss-Newton step
/// moves every line's outline point to its most likely position at once, however far.
/// Gradient exact for this function: (1/N) sum_i w_i (delta_i - mu_i) a_i; Hessian
/// (1/N) sum_i w_i a_i a_i^T, a_i = n_i^T d pi(X_i) / d increment.
///
/// Pose increment: pose_cost.h's delta = (w, v), w a rotation vector (rad, camera axes) about
/// the object centre, v a translation of that centre (m, camera frame). RegionCost
/// (region_cost.h) puts the cue into the coarse-to-fine objective.
///
/// Not thread-safe (per-frame posterior cache, lines): one instance per thread.
class RegionCue {
 public:
  /// Throws std::invalid_argument for a null extractor or settings out of range
  /// (line_half_length_px in [2, 100], line_spacing_px > 0, step_slope_px > 0,
  /// step_amplitude in (0, 0.5)).
  RegionCue(std::shared_ptr<const ContourExtractor> extractor, const RegionCueSettings& settings);

  /// The frame to score (BGR CV_8UC3, undistorted, kept by reference), the colour model (kept
  /// by reference) and the rotation centre of the increments (object frame, m). Resets the
  /// per-pixel posterior cache. Throws std::invalid_argument for another image type.
  void set_frame(const cv::Mat& bgr, const ColorHistograms& histograms,
                 const Eigen::Vector3d& center_object);

  /// Places the correspondence lines at `object_to_camera` (camera: full-resolution
  /// intrinsics of the frame); `scale` >= 1 stretches the lines, spacing and step (coarse
  /// levels: 2, 4). `silhouette` (CV_8UC1 of the camera's size, non-zero on the object rendered
  /// at this pose; empty = no check) keeps only lines on the outer outline: a Contour edge
  /// whose outward side is the object again (a part in front of another, e.g. an arm before the
  /// body, or a back edge the visibility table let through) has no background to separate, and
  /// its all-foreground line would confidently pull the outline outwards by the line's length.
  /// Throws std::logic_error before set_frame(), std::invalid_argument for a silhouette of
  /// another size or type.
  void linearize(const Pose& object_to_camera, const PinholeCamera& camera, double scale = 1.0,
                 const cv::Mat& silhouette = cv::Mat());

  /// Cost at `object_to_camera` with the lines of the last linearize(); when non-null, ADDS
  /// its gradient and Hessian approximation w.r.t. the increment at 0 to `gradient`/`hessian`.
  double evaluate(const Pose& object_to_camera, Vector6d* gradient, Matrix6d* hessian) const;

  /// linearize() then evaluate() at the same pose (no gradient): a pure function of the pose,
  /// 0.5 w_i mu_i^2 averaged: how far the colours say the outline should move.
  double cost_at(const Pose& object_to_camera, const PinholeCamera& camera, double scale = 1.0,
                 const cv::Mat& silhouette = cv::Mat());

  /// Number of lines of the last linearize() (in and out of the image).
  int line_count() const { return static_cast<int>(lines_.size()); }
  const RegionCueSettings& settings() const { return settings_; }

 private:
  struct Line {
    Eigen::Vector3d point_object;
    Eigen::Vector2d centre_px, normal;
    double mean_px = 0.0;  // mu_i
    double weight = 0.0;   // w_i, 1/px^2
  };
  double posterior_at(double x, double y) const;
  /// Reads the line's posteriors and sets its mean and weight. With a silhouette, the line
  /// ends where it meets another part of the object (outwards) or leaves it (inwards): beyond,
  /// its pixels count as unknown.
  void place_line(Line& line, double scale, const cv::Mat& silhouette);
  float pixel_posterior(int x, int y) const;

  std::shared_ptr<const ContourExtractor> extractor_;
  RegionCueSettings settings_;
  cv::Mat bgr_;
  const ColorHistograms* histograms_ = nullptr;
  Eigen::Vector3d center_object_ = Eigen::Vector3d::Zero();
  PinholeCamera camera_;
  double scale_ = 1.0;
  std::vector<Line> lines_;
  std::vector<double> step_table_;      // alpha_h tanh of the step per pixel-offset difference
  std::vector<double> contrast_;        // 2 P_f - 1 per pixel of the line being placed
  std::vector<double> log_likelihood_;  // log p(d) per offset of the line being placed
  mutable cv::Mat posterior_cache_;     // CV_32F, < 0 = not computed yet
  std::vector<ContourSegment> segments_;
};

}  // namespace kct
