#include "klt_contour_tracker/core/pose_refiner.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "klt_contour_tracker/core/basin_hopping.h"
#include "klt_contour_tracker/core/coarse_to_fine_optimizer.h"
#include "klt_contour_tracker/core/contour_cost.h"
#include "klt_contour_tracker/core/contour_energy.h"
#include "klt_contour_tracker/core/contour_extractor.h"
#include "klt_contour_tracker/core/elapsed.h"
#include "klt_contour_tracker/core/keypoint_cost.h"
#include "klt_contour_tracker/core/pose_parametrization.h"
#include "klt_contour_tracker/core/search_area.h"
#include "klt_contour_tracker/core/visibility_table.h"

namespace kct {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
// Numeric-gradient steps move the projected contour by about this much, px (ours): small
// enough to follow the optimum, large enough to see past the bilinear sampling's kinks.
constexpr double kGradientStepPx = 0.5;
// Huber threshold of the keypoint cue, in units of keypoint_sigma_px (ours).
constexpr double kKeypointHuberSigmas = 2.0;
// shift_search_coarse_to_fine: how many of the best coarse shifts get their full-grid
// neighbours scored (ours).
constexpr std::size_t kShiftSearchRefined = 8;

}  // namespace

PoseRefiner::PoseRefiner(std::shared_ptr<const Mesh> mesh, const TrackerParams& params)
    : mesh_(std::move(mesh)), params_(params) {
  visibility_ = VisibilityTable::build(*mesh_, params_.icosphere_subdivisions,
                                       params_.visibility_resolution_px,
                                       params_.visibility_cache_dir);
  extractor_ = std::make_shared<ContourExtractor>(mesh_, visibility_, params_.sharp_edge_angle_deg);
  energy_ = std::make_unique<ContourEnergy>(extractor_, params_.contour_sample_spacing_px);
  size_m_ = mesh_->diameter();
  center_object_ = mesh_->bounding_box_center();
  radius_m_ = mesh_->radius_about(center_object_);
  build_cues();
}

PoseRefiner::~PoseRefiner() = default;

std::unique_ptr<PoseRefiner> PoseRefiner::replica() const {
  std::unique_ptr<PoseRefiner> copy(new PoseRefiner());
  copy->mesh_ = mesh_;
  copy->params_ = params_;
  copy->visibility_ = visibility_;
  copy->extractor_ = std::make_shared<ContourExtractor>(mesh_, visibility_, params_.sharp_edge_angle_deg);
  copy->energy_ = std::make_unique<ContourEnergy>(copy->extractor_, params_.contour_sample_spacing_px);
  copy->size_m_ = size_m_;
  copy->radius_m_ = radius_m_;
  copy->center_object_ = center_object_;
  copy->build_cues();
  return copy;
}

void PoseRefiner::build_cues() {
  contour_cost_ = std::make_shared<ContourCost>(extractor_, params_.contour_sample_spacing_px,
                                                params_.blur_sigma_px, params_.num_threads,
                                                params_.contour_chroma_weight);
  keypoint_cost_ = std::make_shared<KeypointCost>(
      params_.keypoint_sigma_px, kKeypointHuberSigmas * params_.keypoint_sigma_px);
  costs_.clear();
  costs_.add(contour_cost_, params_.contour_weight);
  costs_.add(keypoint_cost_, params_.keypoint_weight);
  for (const auto& [cue, weight] : extra_cues_) costs_.add(cue, weight);
  prepared_gray_.release();
}

void PoseRefiner::add_cue(std::shared_ptr<PoseCost> cue, double weight) {
  costs_.add(cue, weight);  // validates
  extra_cues_.emplace_back(std::move(cue), weight);
  prepared_gray_.release();
}

void PoseRefiner::clear_cues() {
  extra_cues_.clear();
  build_cues();
}

void PoseRefiner::prepare_frame(const cv::Mat& gray, const PinholeCamera& camera,
                                const Pose& predicted, const cv::Mat& bgr) {
  if (params_.optimizer != "coarse_to_fine") return;
  const auto start = std::chrono::steady_clock::now();
  // The same frame as last time (the session refines several hypotheses on one frame): its
  // pyramid is kept. The levels hold the frame's buffer, so it cannot be another frame's.
  std::vector<PyramidLevel> levels;
  const PinholeCamera& kept = cost_frame_.levels.empty() ? camera : cost_frame_.levels[0].camera;
  // The colour levels are made when the contour cue reads their chromaticity.
  const cv::Mat chroma_source = params_.contour_chroma_weight > 0.0 ? bgr : cv::Mat();
  if (static_cast<int>(cost_frame_.levels.size()) == params_.pyramid_levels &&
      cost_frame_.levels[0].gray.data == gray.data &&
      cost_frame_.levels[0].bgr.empty() == chroma_source.empty() &&
      cost_frame_.levels[0].gray.size() == gray.size() && kept.fx() == camera.fx() &&
      kept.fy() == camera.fy() && kept.cx() == camera.cx() && kept.cy() == camera.cy())
    levels = std::move(cost_frame_.levels);
  else
    levels = make_pyramid(gray, camera, params_.pyramid_levels, chroma_source);
  cost_frame_ = PoseCostFrame();
  cost_frame_.levels = std::move(levels);
  cost_frame_.predicted_object_to_camera = cost_frame_.preliminary_object_to_camera = predicted;
  cost_frame_.center_object = center_object_;
  cost_frame_.bgr = bgr;
  costs_.begin_frame(cost_frame_);
  prepared_gray_ = gray;
  prepared_ms_ = elapsed_ms(start);
}

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
  build_cues();
}

double PoseRefiner::energy(const cv::Mat& gray, const PinholeCamera& camera,
                           const Pose& object_to_camera) const {
  return energy_->evaluate(object_to_camera, camera, GradientImage::compute(gray, 0.0));
}

RefineResult PoseRefiner::refine(const cv::Mat& gray, const PinholeCamera& camera,
                                 const Pose& preliminary, const KeypointResult* keypoints,
                                 const cv::Mat& occlusion_mask) {
  if (params_.optimizer == "coarse_to_fine")
    return refine_coarse_to_fine(gray, camera, preliminary, keypoints, occlusion_mask);
  const auto start = std::chrono::steady_clock::now();
  RefineResult result;
  result.object_to_camera = preliminary;
  const double size_m = size_m_;
  const Eigen::Vector3d center_object = center_object_;

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
  result.times.contour_extraction_ms = energy_->extraction_ms();
  result.times.energy_ms = energy_->evaluation_ms() - energy_->extraction_ms();
  energy_->reset_times();
  result.times.optimizer_ms = std::max(
      0.0, elapsed_ms(start) - result.times.contour_extraction_ms - result.times.energy_ms);
  return result;
}

RefineResult PoseRefiner::refine_coarse_to_fine(const cv::Mat& gray, const PinholeCamera& camera,
                                                const Pose& preliminary,
                                                const KeypointResult* keypoints,
                                                const cv::Mat& occlusion_mask) {
  const auto start = std::chrono::steady_clock::now();
  if (prepared_gray_.empty() || prepared_gray_.data != gray.data ||
      prepared_gray_.size() != gray.size())
    prepare_frame(gray, camera, preliminary);
  prepared_gray_.release();
  const double image_ms = prepared_ms_;
  const auto refine_start = std::chrono::steady_clock::now();

  cost_frame_.preliminary_object_to_camera = preliminary;
  cost_frame_.keypoints = keypoints && keypoints->success ? keypoints : nullptr;
  cost_frame_.occlusion_mask = occlusion_mask;
  CoarseToFineSettings settings;
  settings.iterations_per_level = params_.iterations_per_level;
  settings.max_step_px = params_.max_step_px;
  settings.coarsest_level = coarsest_level(camera, preliminary);
  const CoarseToFineOptimizer optimizer;
  // begin_frame() already ran in prepare_frame(): the optimizer must not repeat it.
  // Starts: the preliminary pose and, without keypoints, the best image-plane shift of it
  // (shift_search_diameters). Each is refined; the lowest final cost wins.
  std::vector<Pose> starts{preliminary};
  Pose shifted;
  if (!cost_frame_.keypoints && params_.shift_search_diameters > 0.0 &&
      search_shift(preliminary, settings.coarsest_level, &shifted))
    starts.push_back(shifted);
  CoarseToFineResult optimized;
  int iterations = 0, evaluations = 0;
  for (std::size_t i = 0; i < starts.size(); ++i) {
    CoarseToFineResult run =
        optimizer.minimize(costs_, cost_frame_, starts[i], radius_m_, settings, false);
    iterations += run.iterations;
    evaluations += run.evaluations;
    if (i == 0 || run.final_cost < optimized.final_cost) {
      optimized = run;
    }
  }
  if (starts.size() > 1) {
    // The winner's linearization (what energy() reads below), and the preliminary pose's cost
    // under it (the acceptance test compares the two with the same contour).
    costs_.linearize(optimized.object_to_camera, 0);
    optimized.final_cost = costs_.evaluate(optimized.object_to_camera, nullptr, nullptr);
    optimized.initial_cost = costs_.evaluate(preliminary, nullptr, nullptr);
  }
  optimized.iterations = iterations;
  optimized.evaluations = evaluations;
  RefineResult result;
  result.hops = optimized.iterations;
  result.evaluations = optimized.evaluations;
  // Keep the refined pose only when it lowers the whole objective on the finest level (both
  // poses scored with the contour extracted at the refined pose) and, with keypoints, stays
  // inside the paper's keypoint search area (Sec. 3.4: the inliers' mean reprojection error
  // grows by at most max_reprojection_increase_px), here a test on the result rather than a
  // constraint on the search.
  result.accepted = optimized.final_cost < optimized.initial_cost;
  if (result.accepted && keypoint_cost_->active() &&
      keypoint_cost_->mean_error_px(optimized.object_to_camera) >
          keypoint_cost_->mean_error_px(preliminary) + params_.max_reprojection_increase_px)
    result.accepted = false;
  result.object_to_camera = result.accepted ? optimized.object_to_camera : preliminary;
  // Both with the contour extracted at the refined pose (the optimizer's last linearization):
  // no extra extraction.
  result.energy_after = contour_cost_->energy(result.object_to_camera);
  result.energy_before = contour_cost_->energy(preliminary);

  // Stage times: the contour cue's linearizations are the contour extraction, all evaluations
  // the energy; the rest of the refinement is the optimizer's own work.
  result.times.image_ms = image_ms;
  for (std::size_t i = 0; i < costs_.terms().size(); ++i) {
    const auto& t = costs_.times()[i];
    if (costs_.terms()[i].first == contour_cost_)
      result.times.contour_extraction_ms += t.linearize_ms;
    else
      result.times.energy_ms += t.linearize_ms;
    result.times.energy_ms += t.evaluate_ms;
  }
  result.times.optimizer_ms =
      std::max(0.0, elapsed_ms(refine_start) - result.times.contour_extraction_ms -
                        result.times.energy_ms);
  (void)start;
  return result;
}

int PoseRefiner::coarsest_level(const PinholeCamera& camera, const Pose& preliminary) const {
  int level = params_.pyramid_levels - 1;
  if (!(params_.pyramid_min_object_px > 0.0) || level <= 0) return level;
  const double depth = (preliminary * center_object_).z();
  if (!(depth > 0.0)) return level;
  const double size_px = camera.fx() * size_m_ / depth;
  while (level > 0 && std::ldexp(size_px, -level) < params_.pyramid_min_object_px) --level;
  return level;
}

bool PoseRefiner::search_shift(const Pose& preliminary, int level, Pose* shifted) {
  // An exhaustive search over a disc of shifts at the coarsest level refined (a few hundred to
  // ~1300 evaluations of Eq. 5 over <= kMaxSamples fixed points, no derivatives): cheaper and
  // more predictable than widening the optimizer's basin, and only run when KLT gave no pose.
  const PinholeCamera& camera = cost_frame_.levels[level].camera;
  const Eigen::Vector3d center_camera = preliminary * center_object_;
  if (!(center_camera.z() > 0.0)) return false;
  contour_cost_->linearize(preliminary, level);
  int base_count = 0;
  const double base_energy = contour_cost_->energy(preliminary, &base_count);
  if (base_count == 0) return false;
  const double radius_px =
      params_.shift_search_diameters * size_m_ * camera.fx() / center_camera.z();
  constexpr int kMaxSteps = 20;  // at most a 41 x 41 grid (coarsest-level px steps otherwise)
  const int steps = std::min(kMaxSteps, static_cast<int>(std::ceil(radius_px)));
  if (steps < 1) return false;
  const double step_px = radius_px / steps;
  // A shift must clearly beat staying put (kMinGain x the energy): the object leaving the
  // image or an occluder's edge otherwise lure the pose to whatever edges are near.
  constexpr double kMinGain = 1.5;
  // Grid shift (i, j) steps: (i, j) = (0, 0) is staying put.
  const auto in_disc = [steps](int i, int j) {
    return !(i == 0 && j == 0) && i * i + j * j <= steps * steps;
  };
  const auto shift_of = [&](int i, int j) {
    return Eigen::Vector3d(i * step_px * center_camera.z() / camera.fx(),
                           j * step_px * center_camera.z() / camera.fy(), 0.0);
  };
  // Scored shifts in the order scored; a shift that keeps too few of the points in the image
  // (or the gradients' region of interest) is not comparable.
  std::vector<Eigen::Vector2i> grid;
  std::vector<double> energies;
  std::vector<int> counts;
  const auto score = [&](const std::vector<Eigen::Vector2i>& cells) {
    std::vector<Eigen::Vector3d> shifts;
    for (const Eigen::Vector2i& cell : cells) shifts.push_back(shift_of(cell.x(), cell.y()));
    std::vector<int> cell_counts;
    const std::vector<double> cell_energies =
        contour_cost_->shifted_energies(preliminary, shifts, &cell_counts);
    grid.insert(grid.end(), cells.begin(), cells.end());
    energies.insert(energies.end(), cell_energies.begin(), cell_energies.end());
    counts.insert(counts.end(), cell_counts.begin(), cell_counts.end());
  };
  const auto comparable = [&](std::size_t s) { return counts[s] >= 0.7 * base_count; };
  const int stride = params_.shift_search_coarse_to_fine && steps >= 2 ? 2 : 1;
  const auto on_coarse_grid = [stride](int i, int j) { return i % stride == 0 && j % stride == 0; };
  std::vector<Eigen::Vector2i> cells;
  for (int j = -steps; j <= steps; ++j)
    for (int i = -steps; i <= steps; ++i)
      if (in_disc(i, j) && on_coarse_grid(i, j)) cells.emplace_back(i, j);
  score(cells);
  if (stride > 1) {
    // The full grid's neighbours of the best coarse shifts (staying put is one of them: its
    // neighbours too, a small move is the likeliest).
    std::vector<std::size_t> order;
    for (std::size_t s = 0; s < energies.size(); ++s)
      if (comparable(s)) order.push_back(s);
    const std::size_t keep = std::min<std::size_t>(kShiftSearchRefined, order.size());
    std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(keep), order.end(),
                      [&](std::size_t a, std::size_t b) { return energies[a] > energies[b]; });
    std::vector<Eigen::Vector2i> centres{Eigen::Vector2i::Zero()};
    for (std::size_t k = 0; k < keep; ++k) centres.push_back(grid[order[k]]);
    std::vector<Eigen::Vector2i> fine;
    for (const Eigen::Vector2i& centre : centres)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const Eigen::Vector2i cell(centre.x() + di, centre.y() + dj);
          if (!in_disc(cell.x(), cell.y()) || on_coarse_grid(cell.x(), cell.y()) ||
              std::find(fine.begin(), fine.end(), cell) != fine.end())
            continue;
          fine.push_back(cell);
        }
    score(fine);
  }
  double best_energy = kMinGain * base_energy;
  Eigen::Vector3d best_shift = Eigen::Vector3d::Zero();
  for (std::size_t s = 0; s < grid.size(); ++s) {
    if (!comparable(s) || !(energies[s] > best_energy)) continue;
    best_energy = energies[s];
    best_shift = shift_of(grid[s].x(), grid[s].y());
  }
  if (best_shift.isZero()) return false;
  *shifted = preliminary;
  shifted->translation() += best_shift;
  return true;
}

}  // namespace kct
