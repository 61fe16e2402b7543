#include "klt_contour_tracker/core/search_area.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

namespace kct {

namespace {

void require_positive_size(double object_size_m) {
  if (!(object_size_m > 0.0) || !std::isfinite(object_size_m))
    throw std::invalid_argument("search area: object_size_m must be finite and > 0, got " +
                                std::to_string(object_size_m));
}

int floor_count(double value, int cap) {
  // The epsilon keeps exact products such as 30 * (25000 / 7500) from rounding down to 99.
  const double bounded = std::min(value, static_cast<double>(cap));
  return std::max(1, static_cast<int>(std::floor(bounded + 1e-9)));
}

}  // namespace

bool SearchArea::box_contains(const Vector6d& x) const {
  return (x.array() >= lower.array()).all() && (x.array() <= upper.array()).all();
}

SearchArea make_extrapolated_search_area(double object_size_m, const TrackerParams& params) {
  require_positive_size(object_size_m);
  const double rotation_rad = params.extrapolated_rotation_bound_deg * M_PI / 180.0;
  const double lateral_m = params.extrapolated_lateral_bound * object_size_m;
  const double axial_m = params.extrapolated_axial_bound * object_size_m;
  SearchArea area;
  area.upper << rotation_rad, rotation_rad, rotation_rad, lateral_m, lateral_m, axial_m;
  area.lower = -area.upper;
  return area;
}

ReprojectionConstraint::ReprojectionConstraint(std::vector<Eigen::Vector3d> points_object,
                                               std::vector<Eigen::Vector2d> points_image_px,
                                               const PinholeCamera& camera,
                                               const Pose& pnp_object_to_camera,
                                               double max_increase_px)
    : points_object_(std::move(points_object)),
      points_image_px_(std::move(points_image_px)),
      camera_(camera),
      max_increase_px_(max_increase_px) {
  if (points_object_.empty() || points_object_.size() != points_image_px_.size())
    throw std::invalid_argument(
        "ReprojectionConstraint: points_object and points_image_px must be non-empty and of "
        "equal size, got " +
        std::to_string(points_object_.size()) + " and " + std::to_string(points_image_px_.size()));
  if (!(max_increase_px >= 0.0) || !std::isfinite(max_increase_px))
    throw std::invalid_argument("ReprojectionConstraint: max_increase_px must be in [0, inf), got " +
                                std::to_string(max_increase_px));
  reference_error_px_ = average_error_px(pnp_object_to_camera);
}

double ReprojectionConstraint::average_error_px(const Pose& object_to_camera) const {
  constexpr double kMinDepthM = 1e-3;
  double sum = 0.0;
  for (std::size_t i = 0; i < points_object_.size(); ++i) {
    Eigen::Vector3d p = object_to_camera * points_object_[i];
    p.z() = std::max(p.z(), kMinDepthM);
    sum += (camera_.project(p) - points_image_px_[i]).norm();
  }
  return sum / static_cast<double>(points_object_.size());
}

double ReprojectionConstraint::operator()(const Pose& object_to_camera) const {
  return average_error_px(object_to_camera) - reference_error_px_ - max_increase_px_;
}

SearchArea make_keypoint_search_area(double object_size_m, const TrackerParams& params,
                                     ReprojectionConstraint constraint, double box_scale) {
  if (!(box_scale > 0.0) || !std::isfinite(box_scale))
    throw std::invalid_argument("make_keypoint_search_area: box_scale must be > 0, got " +
                                std::to_string(box_scale));
  SearchArea area = make_extrapolated_search_area(object_size_m, params);
  area.upper *= box_scale;
  // Euler angles beyond +-90 deg would make the box meaningless (and ry is singular there).
  area.upper.head<3>() = area.upper.head<3>().cwiseMin(M_PI / 2.0 * 0.95);
  area.lower = -area.upper;
  area.constraint = std::move(constraint);
  return area;
}

HopCounts hop_counts(std::size_t num_vertices, std::size_t num_faces, const TrackerParams& params) {
  const std::size_t size = num_vertices + num_faces;
  const double s = size == 0 ? std::numeric_limits<double>::infinity()
                             : std::max(1.0, params.hops_budget / static_cast<double>(size));
  HopCounts counts;
  counts.min_hops = floor_count(10.0 * s, params.min_hops_cap);
  counts.max_hops_without_improvement = floor_count(5.0 * s, params.max_hops_without_improvement_cap);
  counts.max_hops = floor_count(30.0 * s, params.max_hops_cap);
  return counts;
}

}  // namespace kct
