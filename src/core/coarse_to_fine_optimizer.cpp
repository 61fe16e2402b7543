#include "klt_contour_tracker/core/coarse_to_fine_optimizer.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kct {

CoarseToFineResult CoarseToFineOptimizer::minimize(PoseCostSum& cost, const PoseCostFrame& frame,
                                                   const Pose& start, double object_radius_m,
                                                   const CoarseToFineSettings& settings,
                                                   bool begin_frame) const {
  if (frame.levels.empty())
    throw std::invalid_argument("CoarseToFineOptimizer: the frame has no pyramid level");
  if (settings.iterations_per_level < 1)
    throw std::invalid_argument("CoarseToFineOptimizer: iterations_per_level must be >= 1");
  if (!(object_radius_m > 0.0))
    throw std::invalid_argument("CoarseToFineOptimizer: object_radius_m must be > 0");
  CoarseToFineResult result;
  result.object_to_camera = start;
  if (begin_frame) cost.begin_frame(frame);

  Pose pose = start;
  int top = static_cast<int>(frame.levels.size()) - 1;
  if (settings.coarsest_level >= 0) top = std::min(top, settings.coarsest_level);
  for (int level = top; level >= 0; --level) {
    const PinholeCamera& camera = frame.levels[level].camera;
    double damping = settings.initial_damping;
    for (int iteration = 0; iteration < settings.iterations_per_level; ++iteration) {
      cost.linearize(pose, level);
      ++result.iterations;
      Vector6d gradient;
      Matrix6d hessian;
      const double value = cost.evaluate(pose, &gradient, &hessian);
      ++result.evaluations;
      if (!(hessian.diagonal().maxCoeff() > 0.0) || !gradient.allFinite()) break;
      const double depth = std::max(1e-6, (pose * frame.center_object).z());
      const double px_per_rad = camera.fx() * object_radius_m / depth;
      const double px_per_m = camera.fx() / depth;
      bool accepted = false;
      double step_px = 0.0;
      for (int attempt = 0; attempt <= settings.max_rejected_steps; ++attempt) {
        Matrix6d damped = hessian;
        // A tiny floor keeps directions no cue constrains from exploding.
        const double floor = 1e-9 * hessian.diagonal().maxCoeff();
        for (int i = 0; i < 6; ++i) damped(i, i) += damping * hessian(i, i) + floor;
        Vector6d delta = damped.ldlt().solve(-gradient);
        if (!delta.allFinite()) break;
        step_px = delta.head<3>().norm() * px_per_rad + delta.tail<3>().norm() * px_per_m;
        if (settings.max_step_px > 0.0 && step_px > settings.max_step_px) {
          delta *= settings.max_step_px / step_px;
          step_px = settings.max_step_px;
        }
        const Pose candidate = apply_pose_increment(pose, delta, frame.center_object);
        const double candidate_value = cost.evaluate(candidate, nullptr, nullptr);
        ++result.evaluations;
        if (candidate_value < value) {
          pose = candidate;
          damping = std::max(1e-6, damping * 0.3);
          accepted = true;
          break;
        }
        damping *= 10.0;
        if (step_px < settings.convergence_px) break;  // the rejected step was tiny anyway
      }
      if (!accepted || step_px < settings.convergence_px) break;
    }
  }
  result.object_to_camera = pose;
  // Costs on the finest level, at the start and the result, with the same linearization.
  cost.linearize(pose, 0);
  result.final_cost = cost.evaluate(pose, nullptr, nullptr);
  result.initial_cost = cost.evaluate(start, nullptr, nullptr);
  result.evaluations += 2;
  return result;
}

}  // namespace kct
