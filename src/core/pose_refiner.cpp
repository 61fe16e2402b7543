#include "klt_contour_tracker/core/pose_refiner.h"

#include <algorithm>
#include <cmath>

#include "klt_contour_tracker/core/basin_hopping.h"
#include "klt_contour_tracker/core/contour_energy.h"
#include "klt_contour_tracker/core/contour_extractor.h"
#include "klt_contour_tracker/core/pose_parametrization.h"
#include "klt_contour_tracker/core/search_area.h"
#include "klt_contour_tracker/core/visibility_table.h"

namespace kct {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
// Numeric-gradient steps move the projected contour by about this much, px (ours): small
// enough to follow the optimum, large enough to see past the bilinear sampling's kinks.
constexpr double kGradientStepPx = 0.5;

}  // namespace

PoseRefiner::PoseRefiner(std::shared_ptr<const Mesh> mesh, const TrackerParams& params)
    : mesh_(std::move(mesh)), params_(params) {
  visibility_ = VisibilityTable::build(*mesh_, params_.icosphere_subdivisions,
                                       params_.visibility_resolution_px,
                                       params_.visibility_cache_dir);
  extractor_ = std::make_shared<ContourExtractor>(mesh_, visibility_, params_.sharp_edge_angle_deg);
  energy_ = std::make_unique<ContourEnergy>(extractor_, params_.contour_sample_spacing_px);
}

PoseRefiner::~PoseRefiner() = default;

void PoseRefiner::set_params(const TrackerParams& params) {
  const bool rebuild_table =
      params.icosphere_subdivisions != params_.icosphere_subdivisions ||
      params.visibility_resolution_px != params_.visibility_resolution_px;
  const bool rebuild_contours = rebuild_table || params.sharp_edge_angle_deg != params_.sharp_edge_angle_deg ||
                                params.contour_sample_spacing_px != params_.contour_sample_spacing_px;
  params_ = params;
  if (rebuild_table)
    visibility_ = VisibilityTable::build(*mesh_, params_.icosphere_subdivisions,
                                         params_.visibility_resolution_px,
                                         params_.visibility_cache_dir);
  if (rebuild_contours) {
    extractor_ = std::make_shared<ContourExtractor>(mesh_, visibility_, params_.sharp_edge_angle_deg);
    energy_ = std::make_unique<ContourEnergy>(extractor_, params_.contour_sample_spacing_px);
  }
}

double PoseRefiner::energy(const cv::Mat& gray, const PinholeCamera& camera,
                           const Pose& object_to_camera) const {
  return energy_->evaluate(object_to_camera, camera, GradientImage::compute(gray, 0.0));
}

RefineResult PoseRefiner::refine(const cv::Mat& gray, const PinholeCamera& camera,
                                 const Pose& preliminary, const KeypointResult* keypoints) {
  RefineResult result;
  result.object_to_camera = preliminary;
  const double size_m = mesh_->diameter();
  const Eigen::Vector3d center_object = mesh_->bounding_box_center();

  // Sec. 3.4: the search area.
  SearchArea area = make_extrapolated_search_area(size_m, params_);
  if (keypoints && !keypoints->inlier_points.points_object.empty()) {
    area = make_keypoint_search_area(
        size_m, params_,
        ReprojectionConstraint(keypoints->inlier_points.points_object,
                               keypoints->inlier_points.points_image, camera,
                               keypoints->object_to_camera, params_.max_reprojection_increase_px));
  }

  // Sec. 3.3: blur, optimize, then a short run on the original frame.
  const GradientImage blurred = GradientImage::compute(gray, params_.blur_sigma_px);
  const GradientImage original = GradientImage::compute(gray, 0.0);
  result.energy_before = energy_->evaluate(preliminary, camera, original);

  const HopCounts counts = hop_counts(mesh_->vertices.size(), mesh_->faces.size(), params_);
  const double depth_m = std::max(1e-6, (preliminary * center_object).z());
  const double size_px = camera.fx() * size_m / depth_m;
  BasinHoppingSettings settings = make_basin_hopping_settings(params_, counts, size_m);
  settings.gradient_step_rotation_rad =
      std::clamp(2.0 * kGradientStepPx / std::max(size_px, 1.0), 1e-4, 0.05);
  settings.gradient_step_translation_m = kGradientStepPx * depth_m / camera.fx();
  settings.seed = params_.random_seed + frame_counter_++;

  const BasinHoppingOptimizer optimizer;
  const PoseParametrization around_preliminary(preliminary, center_object);
  const OptimizationResult coarse = optimizer.maximize(
      [&](const Pose& pose) { return energy_->evaluate(pose, camera, blurred); },
      around_preliminary, area, settings);
  result.hops = coarse.hops;
  result.evaluations = coarse.evaluations;
  result.object_to_camera = coarse.best_pose;

  if (params_.final_hops > 0) {
    // Blur displaces the optimum slightly (Fig. 2): a fixed number of hops on the original
    // frame, from the coarse optimum, in the same search area.
    BasinHoppingSettings final_settings = settings;
    final_settings.min_hops = final_settings.max_hops = params_.final_hops;
    final_settings.max_hops_without_improvement = params_.final_hops;
    const OptimizationResult fine = optimizer.maximize(
        [&](const Pose& pose) { return energy_->evaluate(pose, camera, original); },
        around_preliminary, area, final_settings, coarse.best_x);
    result.hops += fine.hops;
    result.evaluations += fine.evaluations;
    result.object_to_camera = fine.best_pose;
  }
  result.energy_after = energy_->evaluate(result.object_to_camera, camera, original);
  return result;
}

}  // namespace kct
