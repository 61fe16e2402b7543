#pragma once
/// \file motion_model.h
/// Constant-velocity prediction of the object's pose with its uncertainty (ours, beyond the
/// paper, whose extrapolation (Sec. 3.1) uses only the last two poses and no uncertainty).

#include <Eigen/Core>

#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/pose_cost.h"

namespace kct {

// Frame-to-frame motions are pose increments as in pose_cost.h: delta = (w, v), w a rotation
// vector (rad, camera axes) about the object centre, v the centre's translation (m, camera
// frame); the pose after the motion is apply_pose_increment(pose, delta, centre).

/// The increment taking `from` to `to` (exact inverse of apply_pose_increment).
Vector6d motion_increment_between(const Pose& from, const Pose& to,
                                  const Eigen::Vector3d& center_object);

/// Settings of MotionModel (validated by its constructor).
struct MotionModelSettings {
  /// Weight of the newest frame-to-frame motion in the velocity (exponential smoothing), (0, 1].
  double velocity_smoothing = 0.5;
  /// Weight of the newest prediction error in the error variance, (0, 1].
  double error_smoothing = 0.3;
  /// Floors of the prediction's standard deviation: rotation, rad; translation, as a fraction
  /// of the object's size.
  double min_rotation_sigma_rad = 0.5 * M_PI / 180.0;
  double min_translation_sigma = 0.01;
  /// Standard deviation before any motion was seen (after reset()): rotation, rad;
  /// translation, fraction of the object's size.
  double initial_rotation_sigma_rad = 8.0 * M_PI / 180.0;
  double initial_translation_sigma = 0.2;
};

/// Smoothed constant-velocity motion model of one object. update() with each frame's final
/// pose; predict() gives the next frame's expected pose and sigma() the standard deviation of
/// its error per increment component, learned from how wrong past predictions were (hand-held
/// motion: large; a robot arm: small).
class MotionModel {
 public:
  /// `center_object`: rotation centre (object frame, m); `object_size_m` > 0. Throws
  /// std::invalid_argument for a bad size or setting.
  MotionModel(const Eigen::Vector3d& center_object, double object_size_m,
              const MotionModelSettings& settings = {});

  /// Starts over at `object_to_camera`: zero velocity, initial uncertainty.
  void reset(const Pose& object_to_camera);
  /// The frame's final pose. Before reset() it acts as reset().
  void update(const Pose& object_to_camera);
  /// Coasts one frame without a measurement (the pose was not trusted): the last pose moves by
  /// the velocity, and the uncertainty grows by the error variance of one frame.
  void coast();

  bool initialized() const { return initialized_; }
  /// Expected pose of the next frame: the last pose moved by the velocity.
  Pose predict() const;
  /// Standard deviation of predict()'s error per increment component (rad, rad, rad, m, m, m).
  Vector6d sigma() const;
  /// Smoothed velocity, increment per frame.
  const Vector6d& velocity() const { return velocity_; }
  const Pose& last_pose() const { return last_; }
  const Eigen::Vector3d& center_object() const { return center_object_; }

 private:
  Eigen::Vector3d center_object_;
  double size_m_;
  MotionModelSettings settings_;
  bool initialized_ = false;
  Pose last_ = Pose::Identity();
  Vector6d velocity_ = Vector6d::Zero();
  Vector6d variance_ = Vector6d::Zero();        // of the prediction error
  Vector6d coast_variance_ = Vector6d::Zero();  // added by frames without a measurement
};

}  // namespace kct
