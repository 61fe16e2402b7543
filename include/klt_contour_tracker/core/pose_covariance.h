#pragma once
/// \file pose_covariance.h
/// 6x6 covariance of an object_to_camera pose (ours; the paper gives none), ordered as ROS
/// expects in geometry_msgs/PoseWithCovariance (REP 103): x, y, z [m], then rotations about the
/// camera optical frame's fixed x, y, z axes [rad] (roll, pitch, yaw for small angles). The
/// perturbation model is T' = (exp([dtheta]x) R, t + dt): a translation and a small rotation of
/// the object, both expressed in the camera optical frame.

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/tracker_params.h"

namespace kct {

/// 6x6 pose covariance, row/column order x y z roll pitch yaw (m, rad).
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// Gauss-Newton covariance of a pose from 2D-3D correspondences: sigma^2 (J^T J)^-1, J the
/// 2N x 6 Jacobian of the pinhole reprojection residuals at `object_to_camera` and sigma^2 the
/// residuals' variance sum |r|^2 / (2N - 6), floored at min_sigma_px^2 (a perfect fit would
/// otherwise claim a zero covariance). `points_object` in metres (object frame), `points_image`
/// in px on the ideal pinhole image. Returns nullopt with fewer than 4 points, a point not in
/// front of the camera, or a rank-deficient J^T J.
std::optional<Matrix6d> keypoint_pose_covariance(const std::vector<Eigen::Vector3d>& points_object,
                                                 const std::vector<Eigen::Vector2d>& points_image,
                                                 const PinholeCamera& camera,
                                                 const Pose& object_to_camera,
                                                 double min_sigma_px = 0.5);

/// Diagonal covariance for a pose without keypoint support (extrapolated, re-acquired or just
/// initialized): the extrapolated search box of Sec. 3.4 (lateral/axial bounds x object size,
/// rotation bound) taken as +-2 sigma, times `scale`. Throws std::invalid_argument unless
/// object_size_m > 0 and scale > 0.
Matrix6d search_box_pose_covariance(double object_size_m, const TrackerParams& params,
                                    double scale = 1.0);

}  // namespace kct
