#pragma once
/// \file coarse_to_fine_optimizer.h
/// Levenberg-Marquardt minimization of a PoseCostSum over an image pyramid, coarsest level
/// first (the `realtime` preset's refinement; the paper's is basin_hopping.h). Coarse levels
/// widen the capture range (a 2^l times larger basin at level l), fine levels give precision.

#include "klt_contour_tracker/core/pose_cost.h"

namespace kct {

/// Settings of one coarse-to-fine run.
struct CoarseToFineSettings {
  int iterations_per_level = 4;  ///< linearizations per level at most (>= 1)
  /// A level ends early when a step moves no model point by more than this, level px
  /// (estimated from the step and the object's projected size).
  double convergence_px = 0.05;
  double initial_damping = 1e-3;  ///< LM lambda relative to diag(H) at the start of a level
  int max_rejected_steps = 4;     ///< rejected (cost-increasing) steps per iteration
  /// A step that would move a model point by more than this (level px, estimated as for
  /// convergence_px) is shortened to it, direction kept (0 = no limit). Marquardt's
  /// lambda diag(H) does not bound a step along a direction of near-zero curvature that is not
  /// a coordinate axis (a can turning about its own axis, whose outline does not change): the
  /// solve then returns an arbitrarily long step driven by noise.
  double max_step_px = 0.0;
  /// The level to start at (-1 = the pyramid's coarsest; larger values are clamped to it).
  int coarsest_level = -1;
};

/// Outcome of CoarseToFineOptimizer::minimize().
struct CoarseToFineResult {
  Pose object_to_camera = Pose::Identity();  ///< the best pose found
  double initial_cost = 0.0;  ///< cost at the start pose on the finest level
  double final_cost = 0.0;    ///< cost at the result on the finest level
  int iterations = 0;         ///< linearizations (all levels)
  int evaluations = 0;        ///< cost evaluations (all levels)
};

/// Levenberg-Marquardt on pose increments (pose_cost.h), level by level from the coarsest of
/// `frame.levels` to level 0: at each iteration the cues are linearized, the damped normal
/// equations (H + lambda diag(H)) delta = -g solved, and the step kept only when it lowers the
/// cost (otherwise lambda grows by 10 and the step is retried). Deterministic.
class CoarseToFineOptimizer {
 public:
  /// Minimizes `cost` from `start`; calls cost.begin_frame(frame) first unless `begin_frame`
  /// is false (the caller already did). `object_radius_m` (> 0) converts steps to pixels for
  /// the convergence test. Throws std::invalid_argument for a frame without levels or bad
  /// settings.
  CoarseToFineResult minimize(PoseCostSum& cost, const PoseCostFrame& frame, const Pose& start,
                              double object_radius_m, const CoarseToFineSettings& settings,
                              bool begin_frame = true) const;
};

}  // namespace kct
