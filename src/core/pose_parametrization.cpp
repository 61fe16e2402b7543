#include "klt_contour_tracker/core/pose_parametrization.h"

#include <algorithm>
#include <cmath>

namespace kct {

PoseParametrization::PoseParametrization(const Pose& reference_object_to_camera,
                                         const Eigen::Vector3d& center_object)
    : reference_(reference_object_to_camera),
      center_object_(center_object),
      center_camera_(reference_object_to_camera * center_object) {}

Eigen::Matrix3d PoseParametrization::rotation(double rx, double ry, double rz) {
  return (Eigen::AngleAxisd(rz, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(ry, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rx, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Pose PoseParametrization::apply(const Vector6d& x) const {
  const Eigen::Matrix3d r = rotation(x(0), x(1), x(2));
  Pose pose = Pose::Identity();
  pose.linear() = r * reference_.linear();
  pose.translation() =
      r * (reference_.translation() - center_camera_) + center_camera_ + x.tail<3>();
  return pose;
}

Vector6d PoseParametrization::parameters_of(const Pose& object_to_camera) const {
  const Eigen::Matrix3d r = object_to_camera.linear() * reference_.linear().transpose();
  Vector6d x;
  x(0) = std::atan2(r(2, 1), r(2, 2));
  x(1) = std::asin(std::max(-1.0, std::min(1.0, -r(2, 0))));
  x(2) = std::atan2(r(1, 0), r(0, 0));
  x.tail<3>() = object_to_camera * center_object_ - center_camera_;
  return x;
}

}  // namespace kct
