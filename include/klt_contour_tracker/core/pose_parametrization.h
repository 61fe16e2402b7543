#pragma once
/// \file pose_parametrization.h
/// The six optimization parameters of the pose refinement (paper Sec. 3.3-3.4) around a
/// reference pose: x = (rx, ry, rz, tx, ty, tz). (rx, ry, rz) are Euler angles in radians of a
/// rotation about the camera-frame x, y, z axes (R = Rz(rz) Ry(ry) Rx(rx)) applied about the
/// object's centre; (tx, ty, tz) is a translation of that centre in metres in the camera frame.
/// Rotating about the object centre, not about the camera or the object origin, keeps the two
/// groups decoupled: a rotation parameter never moves the centre, a translation parameter never
/// turns the object, so the search-area box (Sec. 3.4) bounds each independently and the
/// optimizer sees a far better conditioned problem.

#include <Eigen/Core>

#include "klt_contour_tracker/core/pose.h"

namespace kct {

/// The six pose parameters (rx, ry, rz [rad], tx, ty, tz [m]); see the file comment.
using Vector6d = Eigen::Matrix<double, 6, 1>;

/// Maps parameter vectors to object_to_camera poses around a fixed reference pose.
class PoseParametrization {
 public:
  /// `reference_object_to_camera`: the pose at x = 0. `center_object`: the rotation centre in
  /// the object frame, metres (the bounding-box centre).
  PoseParametrization(const Pose& reference_object_to_camera, const Eigen::Vector3d& center_object);

  /// The object_to_camera pose for parameters x: T(t) * [rotation R(x) about the centre] *
  /// reference. apply(0) equals the reference exactly.
  Pose apply(const Vector6d& x) const;

  /// Inverse of apply(): the parameters giving `object_to_camera` (Euler angles in
  /// (-pi, pi], ry in [-pi/2, pi/2]).
  Vector6d parameters_of(const Pose& object_to_camera) const;

  /// Camera-frame rotation R = Rz(rz) Ry(ry) Rx(rx), angles in radians.
  static Eigen::Matrix3d rotation(double rx, double ry, double rz);

  const Pose& reference() const { return reference_; }
  /// Rotation centre in the object frame, metres.
  const Eigen::Vector3d& center_object() const { return center_object_; }
  /// Rotation centre at the reference pose, camera frame, metres.
  const Eigen::Vector3d& center_camera() const { return center_camera_; }

 private:
  Pose reference_;
  Eigen::Vector3d center_object_;
  Eigen::Vector3d center_camera_;
};

}  // namespace kct
