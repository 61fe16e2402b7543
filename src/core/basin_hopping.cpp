#include "klt_contour_tracker/core/basin_hopping.h"

#include <nlopt.hpp>

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace kct {

namespace {

constexpr double kFeasibilityTolerance = 1e-7;  // constraint units (px for the reprojection one)
constexpr int kProposalAttemptsPerBase = 3;

/// A point of the (scaled) parameter space with what is known about it.
struct Candidate {
  Vector6d z = Vector6d::Zero();
  double energy = -std::numeric_limits<double>::infinity();
  double constraint = 0.0;
  bool feasible = true;
};

/// Feasible beats infeasible; among infeasible the smaller violation wins; else the higher energy.
bool is_better(const Candidate& a, const Candidate& b) {
  if (a.feasible != b.feasible) return a.feasible;
  if (!a.feasible) return a.constraint < b.constraint;
  return a.energy > b.energy;
}

void require(bool condition, const std::string& message) {
  if (!condition) throw std::invalid_argument("BasinHoppingOptimizer: " + message);
}

void validate(const BasinHoppingSettings& s, const SearchArea& area) {
  require(s.min_hops >= 0, "min_hops must be >= 0");
  require(s.max_hops >= 0, "max_hops must be >= 0");
  require(s.max_hops_without_improvement >= 1, "max_hops_without_improvement must be >= 1");
  require(s.hop_rotation_rad > 0 && std::isfinite(s.hop_rotation_rad), "hop_rotation_rad must be > 0");
  require(s.hop_translation_m > 0 && std::isfinite(s.hop_translation_m),
          "hop_translation_m must be > 0");
  require(s.temperature >= 0 && std::isfinite(s.temperature), "temperature must be >= 0");
  require(s.slsqp_max_evaluations >= 0, "slsqp_max_evaluations must be >= 0");
  require(s.gradient_step_rotation_rad > 0 && s.gradient_step_translation_m > 0,
          "gradient steps must be > 0");
  require(s.improvement_tolerance >= 0, "improvement_tolerance must be >= 0");
  require(area.lower.allFinite() && area.upper.allFinite() &&
              (area.lower.array() <= area.upper.array()).all(),
          "search area needs finite lower <= upper");
}

/// The problem in scaled coordinates z = x / hop std. dev., so that one unit is one typical hop
/// on every axis: SLSQP's quasi-Newton model and its tolerances then see comparable axes
/// (radians and metres differ by orders of magnitude otherwise).
class ScaledProblem {
 public:
  ScaledProblem(const std::function<double(const Pose&)>& energy, const PoseParametrization& param,
                const SearchArea& area, const BasinHoppingSettings& settings)
      : energy_(energy), param_(param), area_(area), settings_(settings) {
    scale_ << settings.hop_rotation_rad, settings.hop_rotation_rad, settings.hop_rotation_rad,
        settings.hop_translation_m, settings.hop_translation_m, settings.hop_translation_m;
    step_.head<3>().setConstant(settings.gradient_step_rotation_rad / settings.hop_rotation_rad);
    step_.tail<3>().setConstant(settings.gradient_step_translation_m / settings.hop_translation_m);
    lower_ = area.lower.cwiseQuotient(scale_);
    upper_ = area.upper.cwiseQuotient(scale_);
  }

  Vector6d to_x(const Vector6d& z) const { return z.cwiseProduct(scale_); }
  Vector6d to_z(const Vector6d& x) const { return x.cwiseQuotient(scale_); }
  Vector6d clip(const Vector6d& z) const { return z.cwiseMax(lower_).cwiseMin(upper_); }
  int evaluations() const { return evaluations_; }

  double energy_at(const Vector6d& z) {
    ++evaluations_;
    const double e = energy_(param_.apply(to_x(z)));
    return std::isnan(e) ? -std::numeric_limits<double>::infinity() : e;
  }

  double constraint_at(const Vector6d& z) const {
    return area_.has_constraint() ? area_.constraint(param_.apply(to_x(z))) : 0.0;
  }

  bool is_feasible(const Vector6d& z) const { return constraint_at(z) <= kFeasibilityTolerance; }

  Candidate evaluate(const Vector6d& z) {
    Candidate c;
    c.z = z;
    c.energy = energy_at(z);
    c.constraint = constraint_at(z);
    c.feasible = c.constraint <= kFeasibilityTolerance;
    return c;
  }

  /// SLSQP from `start` (already evaluated) within the energy budget. Returns the best point it
  /// evaluated (never worse than `start`), whatever way NLopt ended.
  Candidate local_maximize(const Candidate& start) {
    best_ = start;
    start_ = start;
    local_evaluations_ = 0;
    callback_error_ = nullptr;
    const int budget = settings_.slsqp_max_evaluations;
    if (budget < 1 + 2 * 6) return best_;

    nlopt::opt opt(nlopt::LD_SLSQP, 6);
    opt.set_lower_bounds(std::vector<double>(lower_.data(), lower_.data() + 6));
    opt.set_upper_bounds(std::vector<double>(upper_.data(), upper_.data() + 6));
    opt.set_max_objective(&ScaledProblem::objective, this);
    if (area_.has_constraint())
      opt.add_inequality_constraint(&ScaledProblem::constraint, this, 1e-9);
    opt.set_xtol_abs(1e-6);
    opt.set_xtol_rel(1e-10);
    opt.set_maxeval(budget);  // NLopt counts calls; our own counter (gradients included) binds first

    const Vector6d clipped = clip(start.z);
    std::vector<double> x(clipped.data(), clipped.data() + 6);
    double value = 0.0;
    try {
      opt.optimize(x, value);
    } catch (const std::runtime_error&) {
      // roundoff_limited, forced_stop (budget), generic SLSQP failure: keep the best point seen.
    }
    if (callback_error_) std::rethrow_exception(callback_error_);
    return best_;
  }

 private:
  static double objective(unsigned, const double* x, double* grad, void* data) {
    auto* self = static_cast<ScaledProblem*>(data);
    try {
      return self->objective_impl(x, grad);
    } catch (const nlopt::forced_stop&) {
      throw;
    } catch (...) {
      self->callback_error_ = std::current_exception();
      throw nlopt::forced_stop();
    }
  }

  double objective_impl(const double* x, double* grad) {
    const Vector6d z = Eigen::Map<const Vector6d>(x);
    const bool reuse_start = z == start_.z;
    const int needed = (reuse_start ? 0 : 1) + (grad ? 12 : 0);
    if (local_evaluations_ + needed > settings_.slsqp_max_evaluations) throw nlopt::forced_stop();
    local_evaluations_ += needed;

    Candidate c;
    if (reuse_start) {
      c = start_;
    } else {
      c = evaluate(z);
      if (is_better(c, best_)) best_ = c;
    }
    if (grad) {
      for (int i = 0; i < 6; ++i) {
        Vector6d zp = z, zm = z;
        zp(i) += step_(i);
        zm(i) -= step_(i);
        grad[i] = (energy_at(zp) - energy_at(zm)) / (2.0 * step_(i));
        if (!std::isfinite(grad[i])) grad[i] = 0.0;
      }
    }
    return std::isfinite(c.energy) ? c.energy : -std::numeric_limits<double>::max();
  }

  static double constraint(unsigned, const double* x, double* grad, void* data) {
    auto* self = static_cast<ScaledProblem*>(data);
    try {
      const Vector6d z = Eigen::Map<const Vector6d>(x);
      if (grad) {
        for (int i = 0; i < 6; ++i) {
          Vector6d zp = z, zm = z;
          zp(i) += self->step_(i);
          zm(i) -= self->step_(i);
          grad[i] = (self->constraint_at(zp) - self->constraint_at(zm)) / (2.0 * self->step_(i));
        }
      }
      return self->constraint_at(z);
    } catch (...) {
      self->callback_error_ = std::current_exception();
      throw nlopt::forced_stop();
    }
  }

  const std::function<double(const Pose&)>& energy_;
  const PoseParametrization& param_;
  const SearchArea& area_;
  const BasinHoppingSettings& settings_;
  Vector6d scale_, step_, lower_, upper_;
  int evaluations_ = 0;
  int local_evaluations_ = 0;
  Candidate best_, start_;
  std::exception_ptr callback_error_;
};

}  // namespace

bool metropolis_accept(double candidate_energy, double current_energy, double relative_temperature,
                       double uniform_sample) {
  if (candidate_energy >= current_energy) return true;
  const double temperature = relative_temperature * std::abs(current_energy);
  if (!(temperature > 0.0) || !std::isfinite(temperature) || !std::isfinite(candidate_energy))
    return false;
  return uniform_sample < std::exp((candidate_energy - current_energy) / temperature);
}

BasinHoppingSettings make_basin_hopping_settings(const TrackerParams& params, const HopCounts& counts,
                                                 double object_size_m) {
  if (!(object_size_m > 0.0) || !std::isfinite(object_size_m))
    throw std::invalid_argument("make_basin_hopping_settings: object_size_m must be > 0");
  BasinHoppingSettings s;
  s.min_hops = counts.min_hops;
  s.max_hops = counts.max_hops;
  s.max_hops_without_improvement = counts.max_hops_without_improvement;
  s.hop_rotation_rad = params.hop_rotation_deg * M_PI / 180.0;
  s.hop_translation_m = params.hop_translation * object_size_m;
  s.temperature = params.metropolis_temperature;
  s.slsqp_max_evaluations = params.slsqp_max_evaluations;
  s.gradient_step_rotation_rad = 1e-3;
  s.gradient_step_translation_m = 1e-3 * object_size_m;
  s.seed = params.random_seed;
  return s;
}

OptimizationResult BasinHoppingOptimizer::maximize(const std::function<double(const Pose&)>& energy,
                                                   const PoseParametrization& param,
                                                   const SearchArea& area,
                                                   const BasinHoppingSettings& settings,
                                                   const Vector6d& start_x) const {
  validate(settings, area);
  ScaledProblem problem(energy, param, area, settings);
  std::mt19937 rng(settings.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);

  require(start_x.allFinite(), "start_x must be finite");
  const Candidate initial = problem.evaluate(problem.clip(problem.to_z(start_x)));
  Candidate current = problem.local_maximize(initial);
  Candidate best = current;

  // Random hop from the current point; re-drawn with halved steps (then around the best point)
  // while it violates the constraint; the best point itself as the last resort.
  auto propose = [&]() -> Vector6d {
    for (int attempt = 0; attempt < 2 * kProposalAttemptsPerBase; ++attempt) {
      const Vector6d& base = attempt < kProposalAttemptsPerBase ? current.z : best.z;
      const double step = std::ldexp(1.0, -(attempt % kProposalAttemptsPerBase));
      Vector6d z;
      for (int i = 0; i < 6; ++i) z(i) = base(i) + step * normal(rng);
      z = problem.clip(z);
      if (!area.has_constraint() || problem.is_feasible(z)) return z;
    }
    return best.z;
  };

  // Metropolis criterion (maximization) against the current point.
  auto accept = [&](const Candidate& candidate) {
    if (candidate.feasible != current.feasible) return candidate.feasible;
    if (!candidate.feasible) return candidate.constraint < current.constraint;
    if (candidate.energy >= current.energy) return true;
    return metropolis_accept(candidate.energy, current.energy, settings.temperature, uniform(rng));
  };

  int hops = 0;
  int hops_without_improvement = 0;
  while (hops < settings.max_hops) {
    if (hops >= settings.min_hops && hops_without_improvement >= settings.max_hops_without_improvement)
      break;
    const Candidate local = problem.local_maximize(problem.evaluate(propose()));
    ++hops;
    if (accept(local)) current = local;
    bool improved = false;
    if (is_better(local, best)) {
      improved = local.feasible != best.feasible || !local.feasible ||
                 local.energy > best.energy + settings.improvement_tolerance *
                                                  std::max(std::abs(best.energy), 1e-300);
      best = local;
    }
    hops_without_improvement = improved ? 0 : hops_without_improvement + 1;
  }

  OptimizationResult result;
  result.best_x = problem.to_x(best.z);
  result.best_pose = param.apply(result.best_x);
  result.initial_energy = initial.energy;
  result.best_energy = best.energy;
  result.hops = hops;
  result.evaluations = problem.evaluations();
  result.constraint_value = best.constraint;
  result.constraint_satisfied = best.feasible;
  return result;
}

}  // namespace kct
