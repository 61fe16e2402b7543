#include "klt_contour_tracker/core/shadow_map.h"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

#include "klt_contour_tracker/core/renderer.h"

namespace kct {

ShadowMap::ShadowMap(const std::vector<PlacedMesh>& casters,
                     const Eigen::Vector3d& light_direction_camera,
                     const Eigen::Vector3d& target_camera, double radius_m, int resolution_px) {
  if (!(light_direction_camera.norm() > 0.0) || !light_direction_camera.allFinite())
    throw std::invalid_argument("ShadowMap: light_direction_camera must be a non-zero vector");
  if (!(radius_m > 0.0)) throw std::invalid_argument("ShadowMap: radius_m must be > 0");
  if (resolution_px < 16) throw std::invalid_argument("ShadowMap: resolution_px must be >= 16");
  const Eigen::Vector3d towards_light = light_direction_camera.normalized();
  const double distance = 20.0 * radius_m;
  // Light frame: origin at the light, z towards the target.
  const Eigen::Vector3d z_axis = -towards_light;
  const Eigen::Vector3d helper =
      std::abs(z_axis.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d x_axis = helper.cross(z_axis).normalized();
  const Eigen::Vector3d y_axis = z_axis.cross(x_axis);
  Pose light_to_camera = Pose::Identity();
  light_to_camera.linear().col(0) = x_axis;
  light_to_camera.linear().col(1) = y_axis;
  light_to_camera.linear().col(2) = z_axis;
  light_to_camera.translation() = target_camera + distance * towards_light;
  camera_to_light_ = light_to_camera.inverse();

  const double focal = 0.5 * resolution_px * (distance - radius_m) / radius_m;
  const double centre = 0.5 * (resolution_px - 1);
  light_camera_ = PinholeCamera(focal, focal, centre, centre, resolution_px, resolution_px);
  depth_ = cv::Mat(resolution_px, resolution_px, CV_32F, cv::Scalar(0.0f));
  RenderOptions depth_only;
  depth_only.draw_color = false;
  for (const PlacedMesh& caster : casters) {
    if (!caster.mesh) continue;
    const RenderOutput out =
        Renderer(caster.mesh).render(camera_to_light_ * caster.object_to_camera, light_camera_,
                                     depth_only);
    for (int y = 0; y < resolution_px; ++y) {
      const float* src = out.depth.ptr<float>(y);
      float* dst = depth_.ptr<float>(y);
      for (int x = 0; x < resolution_px; ++x)
        if (src[x] > 0.0f && (dst[x] == 0.0f || src[x] < dst[x])) dst[x] = src[x];
    }
  }
  // Two texels of depth slope at 45 deg plus a millimetre: no self-shadowing "acne".
  bias_m_ = 2.0 * (2.0 * radius_m / resolution_px) + 1e-3;
}

double ShadowMap::lit_fraction(const Eigen::Vector3d& point_camera) const {
  const Eigen::Vector3d q = camera_to_light_ * point_camera;
  if (!(q.z() > 0.0)) return 1.0;
  const Eigen::Vector2d pixel = light_camera_.project(q);
  const int cx = static_cast<int>(std::lround(pixel.x())), cy = static_cast<int>(std::lround(pixel.y()));
  int lit = 0, total = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int x = cx + dx, y = cy + dy;
      ++total;
      if (x < 0 || y < 0 || x >= depth_.cols || y >= depth_.rows) {
        ++lit;
        continue;
      }
      const float d = depth_.at<float>(y, x);
      if (d == 0.0f || q.z() <= d + bias_m_) ++lit;
    }
  return static_cast<double>(lit) / total;
}

}  // namespace kct
