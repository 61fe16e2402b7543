#pragma once
/// \file keypoint_cost.h
/// Keypoint reprojection as a PoseCost cue: keeps the refined pose on the KLT + PnP inliers
/// (paper Sec. 3.4 bounds the same quantity by a hard constraint; here it is a soft term in
/// the objective, so the contour cue cannot pull the pose away from good keypoints).

#include <vector>

#include "klt_contour_tracker/core/pose_cost.h"

namespace kct {

/// cost = (1 / N) sum_i rho(|pi(P X_i) - u_i|) / sigma^2 over the frame's RANSAC inliers
/// (X_i object frame, u_i full-resolution px), rho the Huber function with threshold
/// `huber_px` (r^2 below it, 2 k |r| - k^2 above). Gradient and Gauss-Newton Hessian with the
/// Huber weights of the evaluated pose. Inactive without keypoints (extrapolated frames).
class KeypointCost : public PoseCost {
 public:
  /// `sigma_px` > 0 (expected keypoint error, px), `huber_px` > 0. Throws
  /// std::invalid_argument otherwise.
  KeypointCost(double sigma_px, double huber_px);

  std::string name() const override { return "keypoints"; }
  void begin_frame(const PoseCostFrame& frame) override;
  void linearize(const Pose& object_to_camera, int level) override;
  double evaluate(const Pose& object_to_camera, Vector6d* gradient,
                  Matrix6d* hessian) const override;
  bool active() const override { return !points_object_.empty(); }

  /// Mean Euclidean reprojection error of the inliers at a pose, full-resolution px (0 without
  /// keypoints).
  double mean_error_px(const Pose& object_to_camera) const;

 private:
  double sigma_px_, huber_px_;
  const PoseCostFrame* frame_ = nullptr;
  bool loaded_ = false;
  PinholeCamera camera_;
  Eigen::Vector3d center_object_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> points_object_;
  std::vector<Eigen::Vector2d> points_image_;
};

}  // namespace kct
