#pragma once
/// \file trajectory.h
/// Smooth, deterministic (seeded) synthetic object motion and lighting for generated test
/// sequences. The motion groups follow the OPT benchmark (Wu et al., ISMAR 2017) that the
/// paper evaluates on (Sec. 4.2): translation in the image plane, along the optical axis,
/// in-plane rotation, out-of-plane rotation, flashing light, moving light and free motion.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/pose.h"

namespace kct {

/// OPT-style motion group.
enum class MotionGroup { kFree, kXY, kZ, kInPlane, kOutOfPlane, kFlash, kMovingLight };

/// Parses "free", "xy", "z", "inplane", "outofplane", "flash", "movinglight"; throws
/// std::invalid_argument listing the allowed names otherwise.
MotionGroup motion_group_from_string(const std::string& name);
/// The name motion_group_from_string() accepts.
std::string to_string(MotionGroup group);

/// Settings of a synthetic trajectory.
struct TrajectoryParams {
  MotionGroup motion = MotionGroup::kFree;
  int speed = 3;               ///< 1 (slow) .. 5 (fast); scales rotation and translation rates
  uint64_t seed = 1;           ///< same seed, same trajectory
  double distance_min_m = 0.35;  ///< nearest distance of the object centre, metres
  double distance_max_m = 0.6;   ///< farthest distance of the object centre, metres
  double frame_rate_hz = 30.0;   ///< frame i is at time i / frame_rate_hz
};

/// Light of one frame, in the RenderOptions convention.
struct FrameLighting {
  Eigen::Vector3d light_direction_camera{0.3, -0.5, -1.0};  ///< towards the light, camera frame
  double ambient = 0.45;
  double diffuse = 0.65;
  double light_gain = 1.0;
};

/// Continuous-time object trajectory in front of a camera: the model's bounding-box centre
/// stays between the distance bounds and inside the image (with its bounding sphere), the
/// orientation varies around a seeded random start. Every DoF is a sum of three sines with
/// seeded frequencies and phases (C-infinity smooth). When the object would not fit in the
/// image at distance_min_m, both distance bounds are scaled up so that it does.
class SyntheticTrajectory {
 public:
  /// `object_center` and `object_diameter_m` in the object frame (Mesh::bounding_box_center,
  /// Mesh::diameter). Throws std::invalid_argument on a bad speed, distance or diameter.
  SyntheticTrajectory(const TrajectoryParams& params, const PinholeCamera& camera,
                      const Eigen::Vector3d& object_center, double object_diameter_m);

  /// Ground-truth object_to_camera at `time_s` seconds (metres).
  Pose object_to_camera(double time_s) const;
  /// Ground-truth object_to_camera of frame `index`.
  Pose frame_pose(int index) const { return object_to_camera(index / params_.frame_rate_hz); }
  /// Lighting of frame `index` (flashes / a moving light for those groups, else constant).
  FrameLighting frame_lighting(int index) const;

  const TrajectoryParams& params() const { return params_; }
  /// Distance bounds actually used (after fitting the object into the image), metres.
  double distance_min_m() const { return distance_min_; }
  double distance_max_m() const { return distance_max_; }

 private:
  /// Sum of three sines in [-1, 1] for degree of freedom `dof` (0..5) at `time_s`.
  double signal(int dof, double time_s) const;

  TrajectoryParams params_;
  Eigen::Vector3d object_center_;
  double distance_min_ = 0, distance_max_ = 0;
  double lateral_ratio_x_ = 0, lateral_ratio_y_ = 0;  ///< max |x/z|, |y/z| of the centre
  double principal_ratio_x_ = 0, principal_ratio_y_ = 0;  ///< (c - image centre) / f offset
  Eigen::Matrix3d initial_rotation_ = Eigen::Matrix3d::Identity();
  double frequency_hz_[6][3] = {};
  double phase_[6][3] = {};
  double weight_[6][3] = {};
  double flash_levels_[64] = {};
  double in_plane_direction_ = 1.0;
};

/// Settings of a hand-held trajectory (per-frame limits at `frame_rate_hz`).
struct HandheldParams {
  uint64_t seed = 1;             ///< same seed, same trajectory
  int frames = 90;               ///< frames simulated (poses exist for times in [0, frames])
  double frame_rate_hz = 30.0;
  double distance_m = 0.45;      ///< nominal distance of the object centre, metres
  double distance_range_m = 0.12;  ///< the centre stays within distance_m +- this, metres
  /// Hard limits of the centre's motion and of the rotation between consecutive frames.
  double max_translation_m = 0.030;
  double max_rotation_deg = 8.0;
  /// Per-axis standard deviation of the steady (jerk-free) velocity, per frame.
  double typical_translation_m = 0.008;
  double typical_rotation_deg = 2.0;
  /// Probability per frame of a jerk: the velocity is replaced by one in a random direction
  /// at 50-100 % of the limits (a hand starting, stopping or changing direction).
  double jerk_probability = 0.07;
  /// Frames [leave_start_frame, leave_start_frame + leave_frames) pull the object out of the
  /// image sideways; it comes back afterwards. leave_frames = 0: it stays in view.
  int leave_start_frame = -1;
  int leave_frames = 0;
};

/// Hand-held object motion: a damped random walk of the velocity (per-axis AR(1), the
/// "hand tremor and drift"), random jerks, a soft spring that keeps the object near the image
/// centre at the nominal distance and its orientation near an upright start (object z up, seen
/// from 35 deg above, seeded yaw), and hard limits per frame. Simulated once per frame; poses
/// between frames are interpolated (linear centre, slerp rotation) for motion blur.
class HandheldTrajectory {
 public:
  /// `object_center` and `object_diameter_m` in the object frame (Mesh::bounding_box_center,
  /// Mesh::diameter). The nominal distance is increased when the object would not fit in the
  /// image. Throws std::invalid_argument on a non-positive limit, distance, diameter or rate.
  HandheldTrajectory(const HandheldParams& params, const PinholeCamera& camera,
                     const Eigen::Vector3d& object_center, double object_diameter_m);

  /// Ground-truth object_to_camera at `time_s` (clamped to the simulated span), metres.
  Pose object_to_camera(double time_s) const;
  /// Ground-truth object_to_camera of frame `index`.
  Pose frame_pose(int index) const { return object_to_camera(index / params_.frame_rate_hz); }
  /// Object centre in the camera frame at frame `index` (metres).
  Eigen::Vector3d frame_center_camera(int index) const;
  /// Nominal distance actually used (after fitting the object into the image), metres.
  double distance_m() const { return distance_; }
  const HandheldParams& params() const { return params_; }

 private:
  HandheldParams params_;
  Eigen::Vector3d object_center_;
  double distance_ = 0.0;
  std::vector<Eigen::Vector3d> centers_;      ///< per frame, camera frame
  std::vector<Eigen::Quaterniond> rotations_;  ///< per frame, object to camera
};

}  // namespace kct
