#include "klt_contour_tracker/core/motion_model.h"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kct {
namespace {

void check_fraction(double value, const char* name) {
  if (!(value > 0.0 && value <= 1.0))
    throw std::invalid_argument(std::string("MotionModel: ") + name + " must be in (0, 1], got " +
                                std::to_string(value));
}

void check_positive(double value, const char* name) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw std::invalid_argument(std::string("MotionModel: ") + name + " must be > 0, got " +
                                std::to_string(value));
}

}  // namespace

Vector6d motion_increment_between(const Pose& from, const Pose& to,
                                  const Eigen::Vector3d& center_object) {
  const Eigen::AngleAxisd rotation(Eigen::Matrix3d(to.linear() * from.linear().transpose()));
  Vector6d delta;
  delta.head<3>() = rotation.angle() * rotation.axis();
  delta.tail<3>() = to * center_object - from * center_object;
  return delta;
}

MotionModel::MotionModel(const Eigen::Vector3d& center_object, double object_size_m,
                         const MotionModelSettings& settings)
    : center_object_(center_object), size_m_(object_size_m), settings_(settings) {
  check_positive(object_size_m, "object_size_m");
  check_fraction(settings.velocity_smoothing, "velocity_smoothing");
  check_fraction(settings.error_smoothing, "error_smoothing");
  check_positive(settings.min_rotation_sigma_rad, "min_rotation_sigma_rad");
  check_positive(settings.min_translation_sigma, "min_translation_sigma");
  check_positive(settings.initial_rotation_sigma_rad, "initial_rotation_sigma_rad");
  check_positive(settings.initial_translation_sigma, "initial_translation_sigma");
}

void MotionModel::reset(const Pose& object_to_camera) {
  initialized_ = true;
  last_ = object_to_camera;
  velocity_.setZero();
  const double r = settings_.initial_rotation_sigma_rad;
  const double t = settings_.initial_translation_sigma * size_m_;
  variance_ << r * r, r * r, r * r, t * t, t * t, t * t;
  coast_variance_.setZero();
}

void MotionModel::update(const Pose& object_to_camera) {
  if (!initialized_) {
    reset(object_to_camera);
    return;
  }
  const Vector6d motion = motion_increment_between(last_, object_to_camera, center_object_);
  // After coasting, the motion spans several frames' worth of prediction: compare with the
  // prediction from the coasted pose, i.e. the error of predict().
  const Vector6d error = motion_increment_between(predict(), object_to_camera, center_object_);
  const double a = settings_.error_smoothing;
  variance_ = (1.0 - a) * variance_ + a * error.cwiseProduct(error);
  const double b = settings_.velocity_smoothing;
  velocity_ = (1.0 - b) * velocity_ + b * motion;
  last_ = object_to_camera;
  coast_variance_.setZero();
}

void MotionModel::coast() {
  if (!initialized_) return;
  last_ = predict();
  coast_variance_ += variance_;
}

Pose MotionModel::predict() const {
  return apply_pose_increment(last_, velocity_, center_object_);
}

Vector6d MotionModel::sigma() const {
  Vector6d sigma = (variance_ + coast_variance_).cwiseSqrt();
  const double r = settings_.min_rotation_sigma_rad;
  const double t = settings_.min_translation_sigma * size_m_;
  for (int i = 0; i < 3; ++i) sigma[i] = std::max(sigma[i], r);
  for (int i = 3; i < 6; ++i) sigma[i] = std::max(sigma[i], t);
  return sigma;
}

}  // namespace kct
