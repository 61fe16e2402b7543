#pragma once
/// \file shadow_map.h
/// Shadow map of a directional light for synthetic renders (cast shadows in the benchmark's
/// hard sequences): the depth of the shadow casters seen from the light, and a lit-fraction
/// lookup for any camera-frame point.

#include <Eigen/Core>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"

namespace kct {

/// A mesh at a pose in the camera frame (metres).
struct PlacedMesh {
  std::shared_ptr<const Mesh> mesh;
  Pose object_to_camera = Pose::Identity();
};

/// Depth map rendered (with Renderer) from a virtual camera far along the light direction,
/// looking at a target point: for a scene radius r the camera sits 20 r away, so its rays are
/// within 3 deg of parallel (a directional light such as the sun or a distant lamp).
class ShadowMap {
 public:
  /// `light_direction_camera`: towards the light, camera frame (normalized inside);
  /// `target_camera` and `radius_m`: the sphere (camera frame, metres) that must be covered;
  /// `resolution_px`: side of the square depth map. Throws std::invalid_argument on a zero
  /// direction, a radius <= 0 or a resolution < 16.
  ShadowMap(const std::vector<PlacedMesh>& casters, const Eigen::Vector3d& light_direction_camera,
            const Eigen::Vector3d& target_camera, double radius_m, int resolution_px = 512);

  /// Fraction in [0, 1] of a 3 x 3 texel neighbourhood (percentage-closer filtering) in which
  /// `point_camera` is not behind a caster; 1 outside the map.
  double lit_fraction(const Eigen::Vector3d& point_camera) const;

 private:
  Pose camera_to_light_ = Pose::Identity();
  PinholeCamera light_camera_;
  cv::Mat depth_;  ///< CV_32F light-frame z of the nearest caster, 0 where none
  double bias_m_ = 0.0;
};

}  // namespace kct
