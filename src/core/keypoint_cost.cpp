#include "klt_contour_tracker/core/keypoint_cost.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "klt_contour_tracker/core/keypoint_tracker.h"

namespace kct {
namespace {
constexpr double kMinDepth = 1e-3;  // metres: as ReprojectionConstraint
}  // namespace

KeypointCost::KeypointCost(double sigma_px, double huber_px)
    : sigma_px_(sigma_px), huber_px_(huber_px) {
  if (!(sigma_px > 0.0) || !std::isfinite(sigma_px))
    throw std::invalid_argument("KeypointCost: sigma_px must be > 0, got " +
                                std::to_string(sigma_px));
  if (!(huber_px > 0.0) || !std::isfinite(huber_px))
    throw std::invalid_argument("KeypointCost: huber_px must be > 0, got " +
                                std::to_string(huber_px));
}

void KeypointCost::begin_frame(const PoseCostFrame& frame) {
  frame_ = &frame;
  loaded_ = false;
  points_object_.clear();
  points_image_.clear();
}

void KeypointCost::linearize(const Pose&, int) {
  // The keypoints are part of the frame's KLT part: read at the first linearization.
  if (!frame_ || loaded_) return;
  loaded_ = true;
  if (frame_->levels.empty()) return;
  camera_ = frame_->levels[0].camera;
  center_object_ = frame_->center_object;
  const KeypointResult* keypoints = frame_->keypoints;
  if (!keypoints || !keypoints->success ||
      keypoints->inlier_points.points_object.size() != keypoints->inlier_points.points_image.size())
    return;
  points_object_ = keypoints->inlier_points.points_object;
  points_image_ = keypoints->inlier_points.points_image;
}

double KeypointCost::evaluate(const Pose& object_to_camera, Vector6d* gradient,
                              Matrix6d* hessian) const {
  if (points_object_.empty()) return 0.0;
  const Eigen::Vector3d center_camera = object_to_camera * center_object_;
  const double inv_n_sigma2 = 1.0 / (points_object_.size() * sigma_px_ * sigma_px_);
  double sum = 0.0;
  for (std::size_t i = 0; i < points_object_.size(); ++i) {
    Eigen::Vector3d x = object_to_camera * points_object_[i];
    x.z() = std::max(x.z(), kMinDepth);
    const Eigen::Vector2d r = camera_.project(x) - points_image_[i];
    const double norm = r.norm();
    const bool inlier = norm <= huber_px_;
    sum += inlier ? norm * norm : 2.0 * huber_px_ * norm - huber_px_ * huber_px_;
    if (!gradient && !hessian) continue;
    // d rho / d r = 2 w r with the Huber weight w = min(1, k / |r|).
    const double w = inlier ? 1.0 : huber_px_ / norm;
    const Matrix26d j = projection_jacobian(x, center_camera, camera_.fx(), camera_.fy());
    if (gradient) *gradient += (2.0 * w * inv_n_sigma2) * j.transpose() * r;
    if (hessian) *hessian += (2.0 * w * inv_n_sigma2) * j.transpose() * j;
  }
  return sum * inv_n_sigma2;
}

double KeypointCost::mean_error_px(const Pose& object_to_camera) const {
  if (points_object_.empty()) return 0.0;
  double sum = 0.0;
  for (std::size_t i = 0; i < points_object_.size(); ++i) {
    Eigen::Vector3d x = object_to_camera * points_object_[i];
    x.z() = std::max(x.z(), kMinDepth);
    sum += (camera_.project(x) - points_image_[i]).norm();
  }
  return sum / points_object_.size();
}

}  // namespace kct
