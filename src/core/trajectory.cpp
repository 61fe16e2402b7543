#include "klt_contour_tracker/core/trajectory.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace kct {
namespace {

/// SplitMix64: a tiny, fully specified generator, so trajectories are identical on every
/// platform (std:: distributions are implementation-defined).
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) {
    return lo + (hi - lo) * static_cast<double>(next() >> 11) * 0x1.0p-53;
  }
  /// Standard normal (Box-Muller on two uniforms).
  double normal() {
    const double u1 = uniform(1e-12, 1.0), u2 = uniform(0.0, 1.0);
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }
  /// Uniformly distributed unit vector.
  Eigen::Vector3d direction() {
    Eigen::Vector3d d(normal(), normal(), normal());
    return d.norm() > 1e-9 ? Eigen::Vector3d(d.normalized()) : Eigen::Vector3d::UnitX();
  }

 private:
  uint64_t state_;
};

constexpr double kDeg = M_PI / 180.0;

/// Amplitude of each DoF (x, y as a fraction of the lateral bound; z as a fraction of the
/// half distance range; rotations about the camera x, y, z axes in radians) per group.
std::array<double, 6> amplitudes(MotionGroup group) {
  switch (group) {
    case MotionGroup::kXY: return {1.0, 1.0, 0.0, 3 * kDeg, 3 * kDeg, 3 * kDeg};
    case MotionGroup::kZ: return {0.1, 0.1, 1.0, 3 * kDeg, 3 * kDeg, 3 * kDeg};
    case MotionGroup::kInPlane: return {0.1, 0.1, 0.0, 3 * kDeg, 3 * kDeg, 0.0};
    case MotionGroup::kOutOfPlane: return {0.1, 0.1, 0.0, 50 * kDeg, 50 * kDeg, 5 * kDeg};
    case MotionGroup::kFree:
    case MotionGroup::kFlash:
    case MotionGroup::kMovingLight: return {0.7, 0.7, 1.0, 40 * kDeg, 40 * kDeg, 60 * kDeg};
  }
  return {};
}

}  // namespace

MotionGroup motion_group_from_string(const std::string& name) {
  for (MotionGroup g : {MotionGroup::kFree, MotionGroup::kXY, MotionGroup::kZ,
                        MotionGroup::kInPlane, MotionGroup::kOutOfPlane, MotionGroup::kFlash,
                        MotionGroup::kMovingLight})
    if (to_string(g) == name) return g;
  throw std::invalid_argument("unknown motion group '" + name +
                              "' (allowed: free, xy, z, inplane, outofplane, flash, movinglight)");
}

std::string to_string(MotionGroup group) {
  switch (group) {
    case MotionGroup::kFree: return "free";
    case MotionGroup::kXY: return "xy";
    case MotionGroup::kZ: return "z";
    case MotionGroup::kInPlane: return "inplane";
    case MotionGroup::kOutOfPlane: return "outofplane";
    case MotionGroup::kFlash: return "flash";
    case MotionGroup::kMovingLight: return "movinglight";
  }
  return "unknown";
}

SyntheticTrajectory::SyntheticTrajectory(const TrajectoryParams& params,
                                         const PinholeCamera& camera,
                                         const Eigen::Vector3d& object_center,
                                         double object_diameter_m)
    : params_(params), object_center_(object_center) {
  if (params.speed < 1 || params.speed > 5)
    throw std::invalid_argument("trajectory: speed must be in [1, 5], got " +
                                std::to_string(params.speed));
  if (!(params.distance_min_m > 0.0 && params.distance_max_m >= params.distance_min_m))
    throw std::invalid_argument("trajectory: need 0 < distance_min_m <= distance_max_m");
  if (!(object_diameter_m > 0.0 && std::isfinite(object_diameter_m)))
    throw std::invalid_argument("trajectory: object diameter must be > 0");
  if (!(params.frame_rate_hz > 0.0))
    throw std::invalid_argument("trajectory: frame_rate_hz must be > 0");

  // The bounding sphere (radius 0.5 d) must take at most 80 % of the smaller image side.
  const double radius = 0.5 * object_diameter_m;
  const double f_max = std::max(camera.fx(), camera.fy());
  const double needed_min = radius * f_max / (0.4 * std::min(camera.width(), camera.height()));
  const double fit = std::max(1.0, needed_min / params.distance_min_m);
  distance_min_ = params.distance_min_m * fit;
  distance_max_ = params.distance_max_m * fit;

  const double half_w = 0.5 * (camera.width() - 1), half_h = 0.5 * (camera.height() - 1);
  principal_ratio_x_ = (half_w - camera.cx()) / camera.fx();
  principal_ratio_y_ = (half_h - camera.cy()) / camera.fy();
  lateral_ratio_x_ =
      std::max(0.0, 0.8 * (half_w - 1.1 * radius * camera.fx() / distance_min_) / camera.fx());
  lateral_ratio_y_ =
      std::max(0.0, 0.8 * (half_h - 1.1 * radius * camera.fy() / distance_min_) / camera.fy());

  SplitMix64 rng(params.seed * 0x2545F4914F6CDD1DULL + 17);
  const double slow_down =
      (params.motion == MotionGroup::kFlash || params.motion == MotionGroup::kMovingLight) ? 0.5
                                                                                           : 1.0;
  const double speed_factor = slow_down * params.speed / 3.0;
  for (int dof = 0; dof < 6; ++dof) {
    double weight_sum = 0.0;
    for (int k = 0; k < 3; ++k) {
      frequency_hz_[dof][k] = rng.uniform(0.08, 0.25) * speed_factor;
      phase_[dof][k] = rng.uniform(0.0, 2.0 * M_PI);
      weight_[dof][k] = rng.uniform(0.3, 1.0);
      weight_sum += weight_[dof][k];
    }
    for (int k = 0; k < 3; ++k) weight_[dof][k] /= weight_sum;
  }
  // Start: object z up in the image, tilted 30 deg towards the camera, random yaw.
  const double tilt = 30.0 * kDeg;
  Eigen::Matrix3d canonical;
  canonical.col(0) = Eigen::Vector3d(1, 0, 0);
  canonical.col(1) = Eigen::Vector3d(0, -std::sin(tilt), std::cos(tilt));
  canonical.col(2) = Eigen::Vector3d(0, -std::cos(tilt), -std::sin(tilt));
  initial_rotation_ =
      canonical * Eigen::AngleAxisd(rng.uniform(0.0, 2.0 * M_PI), Eigen::Vector3d::UnitZ())
                      .toRotationMatrix();
  in_plane_direction_ = rng.uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0;
  const double levels[] = {0.35, 0.6, 1.0, 1.4, 1.9};
  for (double& level : flash_levels_) level = levels[static_cast<int>(rng.uniform(0.0, 5.0))];
}

double SyntheticTrajectory::signal(int dof, double time_s) const {
  double value = 0.0;
  for (int k = 0; k < 3; ++k)
    value += weight_[dof][k] * std::sin(2.0 * M_PI * frequency_hz_[dof][k] * time_s + phase_[dof][k]);
  return value;
}

Pose SyntheticTrajectory::object_to_camera(double time_s) const {
  const std::array<double, 6> amplitude = amplitudes(params_.motion);
  double s[6];
  for (int dof = 0; dof < 6; ++dof) s[dof] = amplitude[dof] * signal(dof, time_s);

  const double mid = 0.5 * (distance_min_ + distance_max_);
  const double half_range = 0.5 * (distance_max_ - distance_min_);
  const double z = mid + half_range * s[2];
  const Eigen::Vector3d center_camera(z * (principal_ratio_x_ + lateral_ratio_x_ * s[0]),
                                      z * (principal_ratio_y_ + lateral_ratio_y_ * s[1]), z);
  double roll = s[5];
  if (params_.motion == MotionGroup::kInPlane)  // steady spin about the optical axis
    roll = in_plane_direction_ * 0.6 * (params_.speed / 3.0) * time_s;
  const Eigen::Matrix3d delta = (Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(s[4], Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(s[3], Eigen::Vector3d::UnitX()))
                                    .toRotationMatrix();
  Pose pose = Pose::Identity();
  pose.linear() = delta * initial_rotation_;
  pose.translation() = center_camera - pose.linear() * object_center_;
  return pose;
}

FrameLighting SyntheticTrajectory::frame_lighting(int index) const {
  FrameLighting lighting;
  const double time_s = index / params_.frame_rate_hz;
  if (params_.motion == MotionGroup::kFlash) {
    const int block = std::max(2, 12 - 2 * params_.speed);
    lighting.light_gain = flash_levels_[(index / block) % 64];
  } else if (params_.motion == MotionGroup::kMovingLight) {
    const double angle = 2.0 * M_PI * 0.15 * (params_.speed / 3.0) * time_s;
    lighting.light_direction_camera =
        Eigen::Vector3d(0.8 * std::cos(angle), 0.8 * std::sin(angle), -0.6);
    lighting.ambient = 0.25;
    lighting.diffuse = 0.9;
  }
  return lighting;
}

HandheldTrajectory::HandheldTrajectory(const HandheldParams& params, const PinholeCamera& camera,
                                       const Eigen::Vector3d& object_center,
                                       double object_diameter_m)
    : params_(params), object_center_(object_center) {
  if (params.frames < 1) throw std::invalid_argument("handheld trajectory: frames must be >= 1");
  if (!(params.frame_rate_hz > 0.0))
    throw std::invalid_argument("handheld trajectory: frame_rate_hz must be > 0");
  if (!(params.distance_m > 0.0 && params.distance_range_m >= 0.0 &&
        params.distance_range_m < params.distance_m))
    throw std::invalid_argument(
        "handheld trajectory: need distance_m > 0 and 0 <= distance_range_m < distance_m");
  if (!(params.max_translation_m > 0.0 && params.max_rotation_deg > 0.0 &&
        params.typical_translation_m >= 0.0 && params.typical_rotation_deg >= 0.0))
    throw std::invalid_argument("handheld trajectory: speed limits must be > 0");
  if (!(object_diameter_m > 0.0 && std::isfinite(object_diameter_m)))
    throw std::invalid_argument("handheld trajectory: object diameter must be > 0");

  // The bounding sphere must take at most 70 % of the smaller image side at the nearest point.
  const double radius = 0.5 * object_diameter_m;
  const double f_max = std::max(camera.fx(), camera.fy());
  const double needed_near = radius * f_max / (0.35 * std::min(camera.width(), camera.height()));
  distance_ = std::max(params.distance_m, needed_near + params.distance_range_m);
  const double z_min = distance_ - params.distance_range_m, z_max = distance_ + params.distance_range_m;
  // Lateral bound on x/z and y/z that keeps the bounding sphere inside the image.
  const double half_w = 0.5 * (camera.width() - 1), half_h = 0.5 * (camera.height() - 1);
  const double bound_x = std::max(0.0, (half_w - 1.1 * radius * camera.fx() / z_min) / camera.fx());
  const double bound_y = std::max(0.0, (half_h - 1.1 * radius * camera.fy() / z_min) / camera.fy());
  const Eigen::Vector2d principal((half_w - camera.cx()) / camera.fx(),
                                  (half_h - camera.cy()) / camera.fy());

  SplitMix64 rng(params.seed * 0x9E3779B97F4A7C15ULL + 101);
  const double max_rotation = params.max_rotation_deg * kDeg;
  const double persistence = 0.85;  // AR(1) coefficient of the velocity per frame
  const double drive = std::sqrt(1.0 - persistence * persistence);
  const double spring = 0.015;      // per frame^2: a period of about 50 frames
  const double rotation_spring = 0.03;

  // Start: object z up in the image, seen from 35 deg above, random yaw.
  const double tilt = 35.0 * kDeg;
  Eigen::Matrix3d canonical;
  canonical.col(0) = Eigen::Vector3d(1, 0, 0);
  canonical.col(1) = Eigen::Vector3d(0, -std::sin(tilt), std::cos(tilt));
  canonical.col(2) = Eigen::Vector3d(0, -std::cos(tilt), -std::sin(tilt));
  const Eigen::Quaterniond rest(
      canonical *
      Eigen::AngleAxisd(rng.uniform(0.0, 2.0 * M_PI), Eigen::Vector3d::UnitZ()).toRotationMatrix());
  const double leave_side = rng.uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0;

  Eigen::Vector3d center(distance_ * (principal.x() + rng.uniform(-0.3, 0.3) * bound_x),
                         distance_ * (principal.y() + rng.uniform(-0.3, 0.3) * bound_y), distance_);
  Eigen::Quaterniond rotation = rest;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero(), spin = Eigen::Vector3d::Zero();
  for (int i = 0; i <= params.frames; ++i) {
    centers_.push_back(center);
    rotations_.push_back(rotation);
    const bool leaving = params.leave_frames > 0 && i >= params.leave_start_frame &&
                         i < params.leave_start_frame + params.leave_frames;
    // Where the spring pulls: a slowly wandering point near the centre, or out of the image.
    const double t = i / params.frame_rate_hz;
    Eigen::Vector3d target(distance_ * (principal.x() + 0.5 * bound_x * std::sin(0.7 * t + 1.3 * leave_side)),
                           distance_ * (principal.y() + 0.4 * bound_y * std::sin(0.5 * t + 0.4)), distance_);
    if (leaving)
      target.x() = center.z() * (principal.x() + leave_side * (bound_x + 3.0 * radius / z_min +
                                                               0.5 * camera.width() / camera.fx()));
    for (int k = 0; k < 3; ++k) {
      velocity[k] = persistence * velocity[k] + spring * (target[k] - center[k]) +
                    drive * params.typical_translation_m * rng.normal();
      spin[k] = persistence * spin[k] + drive * params.typical_rotation_deg * kDeg * rng.normal();
    }
    const Eigen::AngleAxisd away(rest * rotation.conjugate());  // rotation back to the rest
    spin += rotation_spring * away.angle() * away.axis();
    if (rng.uniform(0.0, 1.0) < params.jerk_probability)
      velocity = rng.uniform(0.5, 1.0) * params.max_translation_m * rng.direction();
    if (rng.uniform(0.0, 1.0) < params.jerk_probability)
      spin = rng.uniform(0.5, 1.0) * max_rotation * rng.direction();
    // Hard limits: the speeds, the distance range and (unless leaving or coming back) the image.
    if (velocity.norm() > params.max_translation_m) velocity *= params.max_translation_m / velocity.norm();
    if (spin.norm() > max_rotation) spin *= max_rotation / spin.norm();
    if ((center.z() + velocity.z() < z_min && velocity.z() < 0) ||
        (center.z() + velocity.z() > z_max && velocity.z() > 0))
      velocity.z() = -velocity.z();
    const bool coming_back = params.leave_frames > 0 && i >= params.leave_start_frame;
    for (int k = 0; k < 2 && !leaving; ++k) {
      const double bound = k == 0 ? bound_x : bound_y;
      const double ratio = (center[k] + velocity[k]) / (center.z() + velocity.z()) - principal[k];
      const bool outside_now = std::abs(center[k] / center.z() - principal[k]) > bound;
      if (std::abs(ratio) > bound && ratio * velocity[k] > 0 && !(coming_back && outside_now))
        velocity[k] = -velocity[k];
    }
    center += velocity;
    if (spin.norm() > 0.0) rotation = Eigen::Quaterniond(Eigen::AngleAxisd(spin.norm(), spin.normalized())) * rotation;
    rotation.normalize();
  }
}

Pose HandheldTrajectory::object_to_camera(double time_s) const {
  const double f = std::clamp(time_s * params_.frame_rate_hz, 0.0, static_cast<double>(params_.frames));
  const int i = std::min(static_cast<int>(std::floor(f)), params_.frames - 1);
  const double alpha = f - i;
  const Eigen::Vector3d center = (1.0 - alpha) * centers_[i] + alpha * centers_[i + 1];
  Pose pose = Pose::Identity();
  pose.linear() = rotations_[i].slerp(alpha, rotations_[i + 1]).toRotationMatrix();
  pose.translation() = center - pose.linear() * object_center_;
  return pose;
}

Eigen::Vector3d HandheldTrajectory::frame_center_camera(int index) const {
  return centers_[std::clamp(index, 0, params_.frames)];
}

}  // namespace kct
