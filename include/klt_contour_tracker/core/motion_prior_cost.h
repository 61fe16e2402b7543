#pragma once
/// \file motion_prior_cost.h
/// The motion model's prediction as a term of the coarse-to-fine objective (pose_cost.h):
/// poses far from where the object was expected to move cost more, in units of the
/// prediction's learned uncertainty (ours, beyond the paper).

#include "klt_contour_tracker/core/motion_model.h"
#include "klt_contour_tracker/core/pose_cost.h"

namespace kct {

/// cost = (1 / 12) sum_i (e_i / sigma_i)^2 with e = motion_increment_between(predicted, pose)
/// (rotation vector about the object centre, rad; centre displacement, m) and sigma the
/// prediction's standard deviation (MotionModel::sigma()): 0.5 at one sigma on every axis,
/// comparable to the other cues' unit scale. Gradient and Hessian w.r.t. the increment:
/// e / (6 sigma^2) and diag(1 / (6 sigma^2)) (first order in e). Inactive until
/// set_prediction().
class MotionPriorCost : public PoseCost {
 public:
  std::string name() const override { return "motion"; }
  /// The frame's predicted pose and its standard deviation (all > 0). Throws
  /// std::invalid_argument for a non-positive sigma.
  void set_prediction(const Pose& predicted_object_to_camera, const Vector6d& sigma);
  void clear() { active_ = false; }
  void begin_frame(const PoseCostFrame& frame) override { center_object_ = frame.center_object; }
  void linearize(const Pose&, int) override {}
  double evaluate(const Pose& object_to_camera, Vector6d* gradient,
                  Matrix6d* hessian) const override;
  bool active() const override { return active_; }

 private:
  bool active_ = false;
  Pose predicted_ = Pose::Identity();
  Vector6d inverse_variance_ = Vector6d::Ones();
  Eigen::Vector3d center_object_ = Eigen::Vector3d::Zero();
};

}  // namespace kct
