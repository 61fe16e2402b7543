#include "klt_contour_tracker/core/pose_covariance.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>

namespace kct {

std::optional<Matrix6d> keypoint_pose_covariance(const std::vector<Eigen::Vector3d>& points_object,
                                                 const std::vector<Eigen::Vector2d>& points_image,
                                                 const PinholeCamera& camera,
                                                 const Pose& object_to_camera,
                                                 double min_sigma_px) {
  const std::size_t n = points_object.size();
  if (n < 4 || points_image.size() != n) return std::nullopt;
  Matrix6d jtj = Matrix6d::Zero();
  double squared_sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d rotated = object_to_camera.linear() * points_object[i];
    const Eigen::Vector3d p = rotated + object_to_camera.translation();
    if (!(p.z() > 1e-6)) return std::nullopt;
    const double inv_z = 1.0 / p.z();
    Eigen::Matrix<double, 2, 3> d_projection;
    d_projection << camera.fx() * inv_z, 0.0, -camera.fx() * p.x() * inv_z * inv_z,  //
        0.0, camera.fy() * inv_z, -camera.fy() * p.y() * inv_z * inv_z;
    // dp/d(dt) = I, dp/d(dtheta) = -[R X]x (left perturbation in the camera frame).
    Eigen::Matrix<double, 3, 6> d_point;
    d_point.leftCols<3>().setIdentity();
    d_point.rightCols<3>() << 0.0, rotated.z(), -rotated.y(),  //
        -rotated.z(), 0.0, rotated.x(),                        //
        rotated.y(), -rotated.x(), 0.0;
    const Eigen::Matrix<double, 2, 6> j = d_projection * d_point;
    jtj += j.transpose() * j;
    squared_sum += (camera.project(p) - points_image[i]).squaredNorm();
  }
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(jtj);
  const double largest = eigen.eigenvalues().maxCoeff();
  if (!(largest > 0.0) || eigen.eigenvalues().minCoeff() <= largest * 1e-12) return std::nullopt;
  const double variance =
      std::max(squared_sum / static_cast<double>(2 * n - 6), min_sigma_px * min_sigma_px);
  Matrix6d covariance = variance * jtj.ldlt().solve(Matrix6d::Identity());
  covariance = 0.5 * (covariance + covariance.transpose());
  if (!covariance.allFinite()) return std::nullopt;
  return covariance;
}

Matrix6d search_box_pose_covariance(double object_size_m, const TrackerParams& params,
                                    double scale) {
  if (!(object_size_m > 0.0) || !(scale > 0.0))
    throw std::invalid_argument("search_box_pose_covariance: object size and scale must be > 0");
  const double lateral_sigma = 0.5 * params.extrapolated_lateral_bound * object_size_m;
  const double axial_sigma = 0.5 * params.extrapolated_axial_bound * object_size_m;
  const double rotation_sigma = 0.5 * params.extrapolated_rotation_bound_deg * M_PI / 180.0;
  Eigen::Matrix<double, 6, 1> variances;
  variances << lateral_sigma * lateral_sigma, lateral_sigma * lateral_sigma,
      axial_sigma * axial_sigma, rotation_sigma * rotation_sigma, rotation_sigma * rotation_sigma,
      rotation_sigma * rotation_sigma;
  return Matrix6d(variances.asDiagonal()) * scale;
}

}  // namespace kct
