#pragma once
/// \file basin_hopping.h
/// Global maximization of a pose objective inside a search area (paper Sec. 3.3): basin hopping
/// (Wales & Doye) with SLSQP (NLopt) as the local optimizer and a numeric central-difference
/// gradient. Generic over the objective: the tracker passes a lambda around the contour energy.

#include <cmath>
#include <cstdint>
#include <functional>

#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/pose_parametrization.h"
#include "klt_contour_tracker/core/search_area.h"
#include "klt_contour_tracker/core/tracker_params.h"

namespace kct {

/// Settings of one basin-hopping run. Hop counts come from hop_counts() (supplement); a run with
/// min_hops = max_hops = N does exactly N hops (the paper's final 5 hops on the unblurred frame).
struct BasinHoppingSettings {
  int min_hops = 10;                     ///< hops always run (unless max_hops is smaller)
  int max_hops = 30;                     ///< hops never exceeded; 0 = a single local optimization
  int max_hops_without_improvement = 5;  ///< after min_hops, stop after this many hops with no new best
  double hop_rotation_rad = 4.0 * M_PI / 180.0;  ///< std. dev. of a hop on each Euler angle, rad
  double hop_translation_m = 0.004;      ///< std. dev. of a hop on each translation, m
  /// Metropolis temperature relative to the energy: T = temperature * |current energy|
  /// (T = 0: only improvements are accepted).
  double temperature = 0.02;
  int slsqp_max_evaluations = 60;        ///< energy evaluations per local optimization (gradients included)
  double gradient_step_rotation_rad = 1e-3;  ///< central-difference step on the Euler angles, rad
  double gradient_step_translation_m = 2e-4; ///< central-difference step on the translations, m
  /// A new best resets the no-improvement count only when it beats the old best by this
  /// fraction of |best| (numeric noise of re-finding the same optimum does not count).
  double improvement_tolerance = 1e-6;
  std::uint32_t seed = 1;                ///< std::mt19937 seed: a run is reproducible
};

/// Settings from the tracker parameters for an object of size `object_size_m`: hop counts from
/// `counts`, hop std. devs. hop_rotation_deg and hop_translation * size, temperature, SLSQP
/// budget and seed from `params`; gradient steps (ours) 1e-3 rad and 1e-3 * size.
BasinHoppingSettings make_basin_hopping_settings(const TrackerParams& params, const HopCounts& counts,
                                                 double object_size_m);

/// Metropolis criterion for a maximization: accepts when candidate >= current, otherwise when
/// uniform_sample (in [0, 1)) < exp((candidate - current) / T) with
/// T = relative_temperature * |current|; T = 0 accepts only improvements.
bool metropolis_accept(double candidate_energy, double current_energy, double relative_temperature,
                       double uniform_sample);

/// Outcome of BasinHoppingOptimizer::maximize().
struct OptimizationResult {
  Pose best_pose = Pose::Identity();  ///< object_to_camera at best_x
  Vector6d best_x = Vector6d::Zero();  ///< best parameters (rad, m), inside the box
  double initial_energy = 0.0;        ///< energy at the start (x = 0: the reference pose)
  double best_energy = 0.0;           ///< energy at best_x
  int hops = 0;                       ///< hops run (the first local optimization not counted)
  int evaluations = 0;                ///< energy evaluations, gradients included
  /// True when there is no constraint or constraint(best_pose) <= 1e-7.
  bool constraint_satisfied = true;
  double constraint_value = 0.0;      ///< constraint(best_pose); 0 without a constraint
};

/// Basin hopping + SLSQP maximizer (Sec. 3.3). Stateless: maximize() may run concurrently.
class BasinHoppingOptimizer {
 public:
  /// Maximizes `energy` over poses param.apply(x), x in `area` (box and optional constraint).
  /// First a local optimization from `start_x` (clipped to the box; x = 0 is the reference pose);
  /// then each hop perturbs the current point (Gaussian, hop std. devs., clipped to the box;
  /// re-drawn with smaller steps when it violates the constraint), optimizes locally, accepts by
  /// the Metropolis criterion and keeps the global best. Never returns a feasible point worse
  /// than the start when the start is feasible. For the paper's final stage on the unblurred
  /// frame, pass the same param and area, start_x = the first stage's best_x and
  /// min_hops = max_hops = 5. Throws std::invalid_argument for inconsistent settings or a box
  /// with lower > upper; exceptions thrown by `energy` or the constraint propagate.
  OptimizationResult maximize(const std::function<double(const Pose&)>& energy,
                              const PoseParametrization& param, const SearchArea& area,
                              const BasinHoppingSettings& settings,
                              const Vector6d& start_x = Vector6d::Zero()) const;
};

}  // namespace kct
