#pragma once
/// \file pose_cost.h
/// The refinement objective of the `realtime` preset as a weighted sum of independent cues
/// (contour energy, keypoint reprojection, and whatever else: a region/colour cue, a motion
/// prior). Each cue gives its value, its analytic gradient and a positive semi-definite Hessian
/// approximation with respect to a six-vector pose increment, so that a Gauss-Newton /
/// Levenberg-Marquardt optimizer (as in SRT3D / M3T) can minimize their sum coarse-to-fine.
///
/// Pose increment: delta = (w, v), w a rotation vector in radians (camera-frame axes, rotation
/// about the object's centre), v a translation of that centre in metres (camera frame):
///   apply_pose_increment(P, delta, c) = T(v) * [Rot(exp(w)) about P * c] * P.
/// At delta = 0 its derivative equals that of PoseParametrization (Euler angles about the same
/// centre), so the two parametrizations agree to first order.
///
/// Protocol, per frame: begin_frame() once (image-only precomputation); then for each pyramid level (coarse to fine) and
/// each optimizer iteration linearize() at the current pose, which fixes what is held constant
/// within a step (the contour, correspondences), then evaluate() at that pose and at candidate
/// poses near it. Values are dimensionless costs (lower = better, about unit scale per cue
/// before weighting) so that cue weights are comparable.

#include <Eigen/Core>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/pose_parametrization.h"

namespace kct {

struct KeypointResult;

/// 6x6 matrix over pose increments (rows/columns: wx, wy, wz [rad], vx, vy, vz [m]).
using Matrix6d = Eigen::Matrix<double, 6, 6>;
/// d(pixel) / d(delta) of one projected point, px per rad and px per m.
using Matrix26d = Eigen::Matrix<double, 2, 6>;

/// The pose `object_to_camera` moved by `delta` (see the file comment): rotation exp(w) about
/// the object centre `center_object` (object frame, m), then translation v (camera frame, m).
Pose apply_pose_increment(const Pose& object_to_camera, const Vector6d& delta,
                          const Eigen::Vector3d& center_object);

/// d(pixel)/d(delta) at delta = 0 of the ideal-pinhole projection of `point_camera` (camera
/// frame, m, z > 0) when the object's centre is at `center_camera` (camera frame, m): the
/// point moves by w x (point - centre) + v. `fx`, `fy` in px (of the pyramid level used).
Matrix26d projection_jacobian(const Eigen::Vector3d& point_camera,
                              const Eigen::Vector3d& center_camera, double fx, double fy);

/// One level of the image pyramid shared by the cues: level l has the frame's size / 2^l.
struct PyramidLevel {
  cv::Mat gray;          ///< CV_8UC1, undistorted
  cv::Mat bgr;           ///< CV_8UC3, this level in colour (given a colour frame), or empty
  PinholeCamera camera;  ///< intrinsics of this level (pixel centres at integer coordinates)
  double scale = 1.0;    ///< this level's pixels per full-resolution pixel (1 / 2^l)
};

/// Per-frame inputs of every cue. The image part (levels, bgr, predicted pose, centre) is set
/// before PoseCost::begin_frame(), which may run while KLT still runs on another thread; the
/// KLT part (preliminary pose, keypoints) is set after it and before the first linearize().
struct PoseCostFrame {
  std::vector<PyramidLevel> levels;  ///< [0] = full resolution; at least one level
  cv::Mat bgr;                       ///< CV_8UC3 undistorted full-resolution frame, or empty
  /// Where the object is expected in this frame before KLT (the previous frame's pose): for
  /// regions of interest in begin_frame(). Expect motion of up to ~1/3 of the object's size.
  Pose predicted_object_to_camera = Pose::Identity();
  Eigen::Vector3d center_object = Eigen::Vector3d::Zero();  ///< rotation centre of the increments
  Pose preliminary_object_to_camera = Pose::Identity();  ///< the pose the refinement starts from
  /// KLT + PnP result of this frame (inliers in full-resolution px), or null when the
  /// preliminary pose was extrapolated.
  const KeypointResult* keypoints = nullptr;
  /// CV_8UC1 at full resolution, nonzero where something may cover the object (contour points
  /// there are not used), or empty; set with the KLT part (occlusion_mask_radius_px).
  cv::Mat occlusion_mask;
};

/// Builds `levels` levels (>= 1) of a PoseCostFrame pyramid from a CV_8UC1 frame and its
/// full-resolution camera (cv::pyrDown; level cameras follow its pixel-centre convention).
/// With `bgr` (CV_8UC3, the same frame in colour) each level also gets its colour image.
std::vector<PyramidLevel> make_pyramid(const cv::Mat& gray, const PinholeCamera& camera, int levels,
                                       const cv::Mat& bgr = cv::Mat());

/// The shading-invariant colour of a CV_8UC3 BGR frame, CV_32FC2: the opponent differences
/// (r - g) / sqrt 2 and (r + g - 2 b) / sqrt 6 divided by the intensity r + g + b (+ 30, so
/// that the sensor noise of dark pixels is not amplified), times 255. A shading change
/// (r, g, b) -> k (r, g, b) leaves it as it is; a change of hue moves it by up to ~200.
cv::Mat chromaticity(const cv::Mat& bgr);

/// One term of the objective. Implementations are not thread-safe (they keep per-frame and
/// per-linearization state); the cue may use threads internally but its result must not
/// depend on how many.
class PoseCost {
 public:
  virtual ~PoseCost() = default;
  /// Short lower-case name ("contour", "keypoints", "region", ...), for logs and stage times.
  virtual std::string name() const = 0;
  /// Per-frame precomputation from the image part of `frame` (image derivatives, colour
  /// statistics); may run concurrently with KLT, so it must not read the KLT part. Called once
  /// per frame before any linearize(); `frame` stays alive (and is completed, see
  /// PoseCostFrame) until the frame's refinement ends: keep a pointer to it.
  virtual void begin_frame(const PoseCostFrame& frame) = 0;
  /// Fixes the state held constant within one optimizer step at `object_to_camera` for pyramid
  /// level `level` (index into PoseCostFrame::levels).
  virtual void linearize(const Pose& object_to_camera, int level) = 0;
  /// Cost at `object_to_camera` with the state of the last linearize(); when non-null, ADDS the
  /// gradient and a positive semi-definite Hessian approximation w.r.t. delta at delta = 0
  /// (around `object_to_camera`) to `gradient` and `hessian`.
  virtual double evaluate(const Pose& object_to_camera, Vector6d* gradient,
                          Matrix6d* hessian) const = 0;
  /// False when the cue has nothing to contribute this frame/level (e.g. no keypoints); the
  /// sum then skips it.
  virtual bool active() const { return true; }
};

/// The weighted sum of cues: value = sum_i w_i cost_i, same for gradient and Hessian.
class PoseCostSum {
 public:
  /// Adds a cue with weight `weight` (>= 0; 0 keeps it out of the sum). Throws
  /// std::invalid_argument for a null cue or a negative / non-finite weight.
  void add(std::shared_ptr<PoseCost> cue, double weight);
  void clear() { terms_.clear(); }

  void begin_frame(const PoseCostFrame& frame);
  void linearize(const Pose& object_to_camera, int level);
  /// Sum of the active cues' weighted costs; gradient and Hessian (when non-null) are SET (not
  /// added to).
  double evaluate(const Pose& object_to_camera, Vector6d* gradient, Matrix6d* hessian) const;

  /// The cues and their weights, in the order added.
  const std::vector<std::pair<std::shared_ptr<PoseCost>, double>>& terms() const { return terms_; }

  /// Wall time of each cue's calls since the last begin_frame() (begin_frame itself included),
  /// milliseconds, in the order of terms().
  struct CueTimes {
    double begin_frame_ms = 0.0, linearize_ms = 0.0, evaluate_ms = 0.0;
  };
  const std::vector<CueTimes>& times() const { return times_; }

 private:
  std::vector<std::pair<std::shared_ptr<PoseCost>, double>> terms_;
  mutable std::vector<CueTimes> times_;
};

}  // namespace kct
