#pragma once
/// \file search_area.h
/// Bounds of the pose search around the preliminary pose (paper Sec. 3.4 and the supplement's
/// "Implementation Settings"): a box in the six pose parameters (pose_parametrization.h),
/// optionally with the non-linear keypoint-consistency constraint, and the number of
/// basin-hopping hops derived from the mesh size.

#include <cstddef>
#include <functional>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/pose_parametrization.h"
#include "klt_contour_tracker/core/tracker_params.h"

namespace kct {

/// Feasible set of the refinement: lower <= x <= upper in parameter space (rad, m) and,
/// when `constraint` is set, constraint(pose) <= 0.
struct SearchArea {
  Vector6d lower = Vector6d::Zero();
  Vector6d upper = Vector6d::Zero();
  /// Optional non-linear constraint on the candidate object_to_camera pose; feasible when <= 0.
  std::function<double(const Pose&)> constraint;

  bool has_constraint() const { return static_cast<bool>(constraint); }
  /// True when x lies in the box (the constraint is not evaluated).
  bool box_contains(const Vector6d& x) const;
};

/// Box used when the preliminary pose was extrapolated (Sec. 3.4): +-extrapolated_rotation_bound_deg
/// on each Euler angle, +-extrapolated_axial_bound * size along camera z and
/// +-extrapolated_lateral_bound * size along camera x and y. No constraint.
/// Throws std::invalid_argument unless object_size_m > 0.
SearchArea make_extrapolated_search_area(double object_size_m, const TrackerParams& params);

/// Keypoint-consistency constraint of Sec. 3.4:
/// AvgReprojErr(P) - AvgReprojErr(P~) - E_max <= 0, where P~ is the PnP pose and
/// AvgReprojErr is the mean Euclidean (not squared) reprojection distance in pixels.
class ReprojectionConstraint {
 public:
  /// `points_object` (object frame, m) and `points_image_px` (px) are the RANSAC inliers;
  /// `pnp_object_to_camera` is P~; `max_increase_px` is E_max. Throws std::invalid_argument
  /// when the point lists are empty or of different sizes or E_max is negative / not finite.
  ReprojectionConstraint(std::vector<Eigen::Vector3d> points_object,
                         std::vector<Eigen::Vector2d> points_image_px, const PinholeCamera& camera,
                         const Pose& pnp_object_to_camera, double max_increase_px);

  /// AvgReprojErr(P) in px. A point at depth < 1 mm is projected as if at 1 mm (keeps the
  /// value finite and huge behind the camera).
  double average_error_px(const Pose& object_to_camera) const;
  /// AvgReprojErr(P) - AvgReprojErr(P~) - E_max, px; feasible when <= 0.
  double operator()(const Pose& object_to_camera) const;

  /// AvgReprojErr(P~), px.
  double reference_error_px() const { return reference_error_px_; }
  double max_increase_px() const { return max_increase_px_; }

 private:
  std::vector<Eigen::Vector3d> points_object_;
  std::vector<Eigen::Vector2d> points_image_px_;
  PinholeCamera camera_;
  double max_increase_px_;
  double reference_error_px_;
};

/// Search area used when KLT succeeded (Sec. 3.4): the reprojection constraint plus a generous
/// box (the extrapolated box scaled by `box_scale`) so that hops stay bounded; the constraint
/// is what actually limits the search. Throws std::invalid_argument unless object_size_m > 0
/// and box_scale > 0.
SearchArea make_keypoint_search_area(double object_size_m, const TrackerParams& params,
                                     ReprojectionConstraint constraint, double box_scale = 2.0);

/// Basin-hopping stop counts of the supplement ("Energy Optimization").
struct HopCounts {
  int min_hops = 1;                      ///< run at least this many hops
  int max_hops_without_improvement = 1;  ///< then stop after this many hops without a new best
  int max_hops = 1;                      ///< never run more
};

/// s = max{1, hops_budget / (|V| + |F|)}; min hops = min{10 s, min_hops_cap}, hops without
/// improvement = min{5 s, max_hops_without_improvement_cap}, max hops = min{30 s, max_hops_cap};
/// each rounded down and at least 1.
HopCounts hop_counts(std::size_t num_vertices, std::size_t num_faces, const TrackerParams& params);

}  // namespace kct
