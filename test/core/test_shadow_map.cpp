#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>

#include "klt_contour_tracker/core/renderer.h"
#include "klt_contour_tracker/core/shadow_map.h"
#include "synthetic_scene.h"

namespace {

using kct::test::make_cube;

kct::Pose at(const Eigen::Vector3d& t) {
  kct::Pose pose = kct::Pose::Identity();
  pose.translation() = t;
  return pose;
}

const kct::PinholeCamera kCamera(500.0, 500.0, 319.5, 239.5, 640, 480);

}  // namespace

// A 10 cm box at 0.5 m, a wall at 0.8 m, light towards +x and the camera (direction
// (0.5, 0, -1)): the shadow on the wall is the box shifted by 0.3 m * 0.5 = 0.15 m towards -x.
TEST(ShadowMap, ShadowFallsWhereTheLightRayHitsTheCaster) {
  const auto box = make_cube(0.1);
  const auto wall = make_cube(1.2);  // only its front face (z = 0.8 - 0.6 ... ) matters
  const Eigen::Vector3d light(0.5, 0.0, -1.0);
  const kct::ShadowMap map({{box, at({0, 0, 0.5})}}, light, Eigen::Vector3d(0, 0, 0.65), 0.4);
  EXPECT_DOUBLE_EQ(map.lit_fraction({-0.15, 0.0, 0.8}), 0.0);   // behind the box along the ray
  EXPECT_DOUBLE_EQ(map.lit_fraction({0.15, 0.0, 0.8}), 1.0);    // the other side: lit
  EXPECT_DOUBLE_EQ(map.lit_fraction({0.0, 0.0, 0.8}), 1.0);     // straight behind: lit (light is oblique)
  EXPECT_DOUBLE_EQ(map.lit_fraction({0.0, 0.0, 0.45}), 1.0);    // the box's own front face
  EXPECT_DOUBLE_EQ(map.lit_fraction({-0.15, 0.2, 0.8}), 1.0);   // beside the shadow
  EXPECT_DOUBLE_EQ(map.lit_fraction({5.0, 5.0, 0.8}), 1.0);     // outside the map
  EXPECT_THROW(kct::ShadowMap({}, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1), 0.4),
               std::invalid_argument);
  EXPECT_THROW(kct::ShadowMap({}, light, Eigen::Vector3d(0, 0, 1), 0.0), std::invalid_argument);
  (void)wall;
}

TEST(ShadowMap, RenderDarkensShadowedPixelsOnly) {
  // The wall: a big box's front face at z = 0.8; the caster: a small box at 0.5 m.
  const auto caster = make_cube(0.1);
  const auto wall = make_cube(1.0);
  const kct::Pose wall_pose = at({0, 0, 1.3});  // front face at z = 0.8
  const Eigen::Vector3d light(0.5, 0.0, -1.0);
  const kct::ShadowMap map({{caster, at({0, 0, 0.5})}, {wall, wall_pose}}, light,
                           Eigen::Vector3d(0, 0, 0.65), 0.5);
  kct::RenderOptions options;
  options.light_direction_camera = light;
  options.specular = 1e-9;
  const kct::Renderer renderer(wall);
  const cv::Mat unshadowed = renderer.render(wall_pose, kCamera, options).color;
  options.shadow_map = &map;
  const cv::Mat shadowed = renderer.render(wall_pose, kCamera, options).color;
  const Eigen::Vector2d in_shadow = kCamera.project({-0.15, 0.0, 0.8});
  const Eigen::Vector2d lit = kCamera.project({0.15, 0.0, 0.8});
  const auto grey = [](const cv::Mat& image, const Eigen::Vector2d& p) {
    return static_cast<int>(image.at<cv::Vec3b>(static_cast<int>(p.y()), static_cast<int>(p.x()))[1]);
  };
  EXPECT_LT(grey(shadowed, in_shadow), grey(unshadowed, in_shadow) - 40);
  EXPECT_EQ(grey(shadowed, lit), grey(unshadowed, lit));
}
