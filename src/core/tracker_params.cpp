#include "klt_contour_tracker/core/tracker_params.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace kct {
namespace {

template <typename T>
void check_range(const char* name, T value, T lo, T hi) {
  if (!(value >= lo && value <= hi)) {  // also rejects NaN
    std::ostringstream msg;
    msg << "TrackerParams." << name << " = " << value << " is outside the allowed range [" << lo
        << ", " << hi << "]";
    throw std::invalid_argument(msg.str());
  }
}

}  // namespace

void TrackerParams::validate() const {
  check_range("max_keypoints", max_keypoints, 8, 100000);
  check_range("corner_quality_level", corner_quality_level, 1e-6, 1.0);
  check_range("corner_min_distance_px", corner_min_distance_px, 0.0, 1000.0);
  check_range("klt_window_px", klt_window_px, 5, 201);
  if (klt_window_px % 2 == 0)
    throw std::invalid_argument("TrackerParams.klt_window_px must be odd");
  check_range("klt_pyramid_levels", klt_pyramid_levels, 0, 8);
  check_range("klt_forward_backward_px", klt_forward_backward_px, 0.01, 100.0);
  check_range("ransac_reprojection_px", ransac_reprojection_px, 0.1, 100.0);
  check_range("ransac_iterations", ransac_iterations, 1, 100000);
  check_range("klt_min_points", klt_min_points, 4, 100000);
  check_range("klt_min_inlier_ratio", klt_min_inlier_ratio, 0.0, 1.0);
  check_range("redetect_ratio", redetect_ratio, 0.0, 1.0);
  check_range("redetect_interval_frames", redetect_interval_frames, 0, 1000000);
  check_range("sharp_edge_angle_deg", sharp_edge_angle_deg, 0.0, 180.0);
  check_range("icosphere_subdivisions", icosphere_subdivisions, 0, 6);
  check_range("visibility_resolution_px", visibility_resolution_px, 16, 4096);
  check_range("contour_sample_spacing_px", contour_sample_spacing_px, 0.1, 100.0);
  check_range("blur_sigma_px", blur_sigma_px, 0.0, 20.0);
  check_range("final_hops", final_hops, 0, 10000);
  check_range("hops_budget", hops_budget, 1.0, 1e12);
  check_range("min_hops_cap", min_hops_cap, 0, 100000);
  check_range("max_hops_without_improvement_cap", max_hops_without_improvement_cap, 1, 100000);
  check_range("max_hops_cap", max_hops_cap, 1, 100000);
  if (min_hops_cap > max_hops_cap)
    throw std::invalid_argument("TrackerParams.min_hops_cap must be <= max_hops_cap");
  check_range("max_reprojection_increase_px", max_reprojection_increase_px, 0.0, 1000.0);
  check_range("extrapolated_rotation_bound_deg", extrapolated_rotation_bound_deg, 0.0, 180.0);
  check_range("extrapolated_axial_bound", extrapolated_axial_bound, 0.0, 10.0);
  check_range("extrapolated_lateral_bound", extrapolated_lateral_bound, 0.0, 10.0);
  check_range("hop_rotation_deg", hop_rotation_deg, 0.0, 180.0);
  check_range("hop_translation", hop_translation, 0.0, 10.0);
  check_range("metropolis_temperature", metropolis_temperature, 1e-9, 1e9);
  check_range("slsqp_max_evaluations", slsqp_max_evaluations, 1, 1000000);
}

std::vector<std::string> preset_names() { return {"paper", "klt_only"}; }

TrackerParams make_preset(const std::string& name) {
  TrackerParams params;  // the defaults are the paper's values
  if (name == "paper") return params;
  if (name == "klt_only") {
    params.refine = false;
    return params;
  }
  std::string known;
  for (const auto& n : preset_names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown preset '" + name + "' (known: " + known + ")");
}

}  // namespace kct
