#pragma once
/// \file contour_cost.h
/// The contour energy (paper Eq. 5) as a PoseCost cue with an analytic gradient: the contour
/// is extracted once per linearization and only re-projected inside an optimizer step.

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "klt_contour_tracker/core/contour_extractor.h"
#include "klt_contour_tracker/core/pose_cost.h"
#include "klt_contour_tracker/core/worker_threads.h"

namespace kct {

/// Eq. 5 over points held fixed on the model between linearizations.
///
/// linearize() extracts the Contour / Sharp edges at the pose (Algorithm 1; again only when
/// the camera centre moved by more than 1% of its distance to the object since the frame's last
/// extraction, otherwise the same edges are re-projected) and puts sample points every spacing_px (level px) along the projected edges taken one
/// after the other (the remainder carried over from edge to edge; the spacing grows so that
/// there are at most kMaxSamples), at the matching fraction of each 3D edge. evaluate()
/// re-projects those points and the edges' normals and returns
///   cost = -E / c,  E = mean over in-image points of |grad I(p) . n|   (Eq. 5 on the level),
/// c = the level's contrast scale (8 x the mean gradient magnitude around the object), so a
/// well-aligned contour costs about -1 whatever the image's contrast. The gradient is exact for
/// this function (the derivative of the bilinear interpolation of the gradient images, which
/// are computed once per frame and level; the normals' rotation included): no extra energy
/// evaluation per gradient, unlike the paper preset's numeric gradient (12 per gradient). The
/// Hessian approximation is sum_k (f_k / sigma^2) a_k a_k^T / (N c), a_k = n_k^T d p_k /
/// d delta, f_k = |grad I . n|, sigma the edge width in level px: for an edge whose response
/// across it is Gaussian of width sigma, the Newton step then moves each point exactly onto
/// the edge's crest (it is Newton's method on log f), so far points converge in one step.
///
/// Gradient images are computed per level inside a region around the object's projection at
/// the frame's predicted pose (margin: the projected size + 32 px); points outside it are
/// dropped as if outside the image.
class ContourCost : public PoseCost {
 public:
  /// Most sample points per linearization: bounds the cost whatever the mesh and resolution.
  static constexpr int kMaxSamples = 1000;

  /// `spacing_px` (> 0): sample spacing in level px. `blur_sigma_px` (>= 0): Gaussian blur of
  /// each level before differentiating (widens the basin). `num_threads` (>= 1): threads for
  /// the per-frame image derivatives; the result does not depend on it. Throws
  /// std::invalid_argument for a null extractor or bad values.
  /// `chroma_weight` > 0: where the frame's levels carry their colour image (PyramidLevel::bgr),
  /// f_k = |grad I . n| + chroma_weight * sum over the two chromaticity() channels of
  /// |grad C . n|.
  ContourCost(std::shared_ptr<const ContourExtractor> extractor, double spacing_px,
              double blur_sigma_px, int num_threads = 1, double chroma_weight = 0.0);

  std::string name() const override { return "contour"; }
  void begin_frame(const PoseCostFrame& frame) override;
  void linearize(const Pose& object_to_camera, int level) override;
  double evaluate(const Pose& object_to_camera, Vector6d* gradient,
                  Matrix6d* hessian) const override;
  bool active() const override { return !samples_.empty(); }

  /// Eq. 5 (intensity units per level px) at `object_to_camera` over the fixed points of the
  /// last linearize(), and the number of points kept; for tests and diagnostics.
  double energy(const Pose& object_to_camera, int* num_points = nullptr) const;
  /// energy() at `object_to_camera` moved by each of `shifts_camera` (camera-frame
  /// translations parallel to the image plane: z = 0, else std::invalid_argument), with each
  /// shift's number of points in `num_points` (resized): the fixed points are projected once for
  /// all shifts (the refiner's shift search scores up to ~1300 shifts of one pose).
  std::vector<double> shifted_energies(const Pose& object_to_camera,
                                       const std::vector<Eigen::Vector3d>& shifts_camera,
                                       std::vector<int>* num_points) const;
  /// The contrast scale c of the current level (see the class comment).
  double contrast_scale() const;
  /// Edge width sigma (level px) used by the Hessian approximation: sqrt(blur^2 + 1).
  double edge_width_px() const { return edge_width_px_; }

 private:
  /// The level whose chromaticity derivatives `level` reads (-1: none).
  int chroma_level(int level) const;
  /// Per level: image derivatives inside `roi` (level px), CV_32F, origin at roi.tl().
  struct LevelImages {
    cv::Rect roi;
    cv::Mat gx, gy;
    /// The chromaticity channels' derivatives times chroma_weight (empty: grey only).
    cv::Mat chroma_gx[2], chroma_gy[2];
    double chroma_contrast = 0.0;  ///< the chromaticity's share of `contrast` (its own level)
    double contrast = 1.0;
  };
  struct Segment {
    Eigen::Vector3d a_object, b_object;
    int first_sample, end_sample;
  };
  /// Sum of f_k (and derivative sums when requested) over the fixed points.
  double accumulate(const Pose& object_to_camera, int* count, Vector6d* gradient,
                    Matrix6d* hessian) const;

  std::shared_ptr<const ContourExtractor> extractor_;
  double spacing_px_;
  double blur_sigma_px_;
  double chroma_weight_;
  double edge_width_px_;
  Eigen::Vector3d center_object_;  ///< the mesh's bounding-box centre, object frame, m
  double radius_m_ = 0.0;          ///< the mesh's bounding-sphere radius about it, m
  std::unique_ptr<WorkerThreads> workers_;  ///< num_threads threads, the caller's included
  const PoseCostFrame* frame_ = nullptr;
  std::vector<LevelImages> levels_;
  /// The pyramid levels_ were computed from (headers held, so their buffers are not reused
  /// while they are the key): a begin_frame() on the same levels with the same regions keeps
  /// levels_ (the session refines a dozen hypotheses around one place on one frame).
  std::vector<cv::Mat> levels_source_;
  int level_ = 0;
  std::vector<Segment> segments_;
  std::vector<Eigen::Vector3d> samples_;  ///< object frame, m
  std::vector<ContourSegment> scratch_;  ///< the edges of the last extraction
  bool extracted_ = false;                ///< scratch_ holds this frame's edges
  Eigen::Vector3d extracted_camera_ = Eigen::Vector3d::Zero();  ///< camera centre then, object frame
};

}  // namespace kct
