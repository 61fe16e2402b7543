#include "klt_contour_tracker/core/pose.h"

#include <algorithm>
#include <cmath>

namespace kct {

bool is_valid_pose(const Pose& pose) {
  if (!pose.matrix().allFinite()) return false;
  const Eigen::Matrix3d r = pose.linear();
  return (r * r.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-6 && r.determinant() > 0;
}

Pose extrapolate_pose(const Pose& object_to_camera_i2, const Pose& object_to_camera_i1) {
  // Motion of the object in the camera frame from i-2 to i-1, applied once more.
  const Pose motion = object_to_camera_i1 * object_to_camera_i2.inverse();
  Pose predicted = motion * object_to_camera_i1;
  // Re-orthonormalize: repeated products accumulate rounding.
  predicted.linear() = Eigen::Quaterniond(predicted.linear()).normalized().toRotationMatrix();
  return predicted;
}

double rotation_error_deg(const Pose& a, const Pose& b) {
  const Eigen::Matrix3d relative = a.linear().transpose() * b.linear();
  const double c = std::clamp((relative.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

double translation_error(const Pose& a, const Pose& b) {
  return (a.translation() - b.translation()).norm();
}

Pose pose_from_row(const std::array<double, 12>& row) {
  Pose pose = Pose::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) pose.linear()(r, c) = row[3 * r + c];
  pose.translation() = Eigen::Vector3d(row[9], row[10], row[11]);
  return pose;
}

std::array<double, 12> pose_to_row(const Pose& pose) {
  std::array<double, 12> row{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) row[3 * r + c] = pose.linear()(r, c);
  for (int i = 0; i < 3; ++i) row[9 + i] = pose.translation()(i);
  return row;
}

Pose pose_from_quaternion(double x, double y, double z, double qx, double qy, double qz,
                          double qw) {
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
  pose.translation() = Eigen::Vector3d(x, y, z);
  return pose;
}

}  // namespace kct
