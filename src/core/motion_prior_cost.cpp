#include "klt_contour_tracker/core/motion_prior_cost.h"

#include <stdexcept>

namespace kct {

void MotionPriorCost::set_prediction(const Pose& predicted_object_to_camera,
                                     const Vector6d& sigma) {
  if (!(sigma.minCoeff() > 0.0) || !sigma.allFinite())
    throw std::invalid_argument("MotionPriorCost::set_prediction: sigma must be > 0 and finite");
  predicted_ = predicted_object_to_camera;
  inverse_variance_ = sigma.cwiseProduct(sigma).cwiseInverse();
  active_ = true;
}

double MotionPriorCost::evaluate(const Pose& object_to_camera, Vector6d* gradient,
                                 Matrix6d* hessian) const {
  if (!active_) return 0.0;
  const Vector6d e = motion_increment_between(predicted_, object_to_camera, center_object_);
  const Vector6d weighted = e.cwiseProduct(inverse_variance_) / 6.0;
  if (gradient) *gradient += weighted;
  if (hessian) hessian->diagonal() += inverse_variance_ / 6.0;
  return 0.5 * e.dot(weighted);
}

}  // namespace kct
