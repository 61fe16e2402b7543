// SurfaceTexture: surface colours learned at one pose tell the right pose from the same object
// turned about one of its axes, under another light, and an untextured object is not used.
#include <gtest/gtest.h>

#include "klt_contour_tracker/core/surface_texture.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

/// `pose` turned by `angle_deg` about the object's own axis `axis_object` through its origin.
Pose turned_about_own_axis(const Pose& pose, double angle_deg, const Eigen::Vector3d& axis_object) {
  Pose turned = pose;
  turned.linear() = pose.linear() * Eigen::AngleAxisd(angle_deg * M_PI / 180.0, axis_object).toRotationMatrix();
  return turned;
}

struct TextureScene {
  std::shared_ptr<Mesh> mesh = std::make_shared<Mesh>(test::make_box(0.1, 0.1, 0.1));
  Renderer renderer{mesh};
  PinholeCamera camera = test::make_camera();
  cv::Mat background = test::make_background(camera.size(), 5);
  Pose start = test::make_pose(0.45);
  cv::Mat frame(const Pose& pose, int seed, double light_gain = 1.0) const {
    RenderOptions options;
    options.light_gain = light_gain;
    return test::render_frame(renderer, camera, pose, background, 2.0, seed, options);
  }
};

TEST(SurfaceTexture, TellsTheRightPoseFromTheObjectTurnedAboutItsAxis) {
  const TextureScene scene;
  SurfaceTexture texture(scene.mesh);
  EXPECT_FALSE(texture.ready());
  texture.learn(scene.frame(scene.start, 1), scene.start, scene.camera);
  ASSERT_TRUE(texture.ready());
  EXPECT_GE(texture.size(), SurfaceTexture::kMinPoints);
  // The cube turned 90 deg about its own z axis has the same outline, not the same surface.
  const Pose turned = turned_about_own_axis(scene.start, 90.0, Eigen::Vector3d::UnitZ());
  for (const double gain : {1.0, 0.6}) {  // the light dimmed to 60 %: the correlation ignores gain
    const cv::Mat frame = scene.frame(scene.start, 2, gain);
    const PreparedFrame prepared = texture.prepare(frame, scene.start, scene.camera);
    const TextureAgreement right = texture.agreement(prepared, scene.start, scene.camera);
    const TextureAgreement wrong = texture.agreement(prepared, turned, scene.camera);
    // Tolerances: sensor noise of 2 grey levels leaves the right pose near 1 (measured 0.9+);
    // the turned one shows other faces' random texture (measured near 0).
    EXPECT_GE(right.points, SurfaceTexture::kMinPoints);
    EXPECT_GT(right.correlation, 0.8) << "gain " << gain;
    EXPECT_LT(wrong.correlation, 0.4) << "gain " << gain;
  }
  // Shown turned, the turned pose is the one that matches.
  const cv::Mat shown_turned = scene.frame(turned, 3);
  const PreparedFrame prepared = texture.prepare(shown_turned, turned, scene.camera);
  EXPECT_GT(texture.agreement(prepared, turned, scene.camera).correlation, 0.8);
  EXPECT_LT(texture.agreement(prepared, scene.start, scene.camera).correlation, 0.4);
}

TEST(SurfaceTexture, AColourPatternIsToldFromABrightnessPattern) {
  TextureScene scene;
  SurfaceTexture texture(scene.mesh);
  texture.learn(scene.frame(scene.start, 1), scene.start, scene.camera);
  ASSERT_TRUE(texture.ready());
  EXPECT_TRUE(texture.has_color_pattern()) << "random colours";
  // The same texture in grey: a pattern, but not in the colours.
  auto grey_box = std::make_shared<Mesh>(*scene.mesh);
  cv::cvtColor(grey_box->texture, grey_box->texture, cv::COLOR_BGR2GRAY);
  cv::cvtColor(grey_box->texture, grey_box->texture, cv::COLOR_GRAY2BGR);
  const Renderer renderer(grey_box);
  SurfaceTexture grey_texture(grey_box);
  grey_texture.learn(test::render_frame(renderer, scene.camera, scene.start, scene.background, 2.0, 1),
                     scene.start, scene.camera);
  EXPECT_TRUE(grey_texture.ready());
  EXPECT_FALSE(grey_texture.has_color_pattern());
}

TEST(SurfaceTexture, AnUntexturedObjectOrAMissingOneIsNotUsed) {
  TextureScene scene;
  SurfaceTexture texture(scene.mesh);
  // The object behind the camera: nothing to learn.
  Pose behind = scene.start;
  behind.translation().z() = -0.45;
  texture.learn(scene.frame(scene.start, 1), behind, scene.camera);
  EXPECT_FALSE(texture.ready());
  EXPECT_EQ(texture.size(), 0);
  // A grey frame is not a colour frame.
  cv::Mat grey(scene.camera.size(), CV_8UC1, cv::Scalar(100));
  texture.learn(grey, scene.start, scene.camera);
  EXPECT_FALSE(texture.ready());
  // A uniformly coloured cube: flat faces, no pattern.
  auto plain = std::make_shared<Mesh>(test::make_box(0.1, 0.1, 0.1, false));
  const Renderer renderer(plain);
  SurfaceTexture plain_texture(plain);
  plain_texture.learn(test::render_frame(renderer, scene.camera, scene.start, scene.background, 2.0, 1),
                      scene.start, scene.camera);
  EXPECT_FALSE(plain_texture.ready());
  EXPECT_FALSE(plain_texture.has_color_pattern());
}

/// best_shift(): the cube shown at its pose, the held pose 3 cm to the side and 3.6 cm (8 %)
/// too far: the learned colours disagree there, and the grid of shifts finds where they agree.
TEST(SurfaceTexture, AShiftFindsWhereThePrintedSurfaceIs) {
  const TextureScene scene;
  SurfaceTexture texture(scene.mesh);
  texture.learn(scene.frame(scene.start, 1), scene.start, scene.camera);
  ASSERT_TRUE(texture.has_color_pattern());
  Pose held = scene.start;
  held.translation() += Eigen::Vector3d(0.03, -0.01, 0.08 * scene.start.translation().z());
  const cv::Mat shown = scene.frame(scene.start, 2);
  const PreparedFrame prepared = texture.prepare(shown, held, scene.camera);
  const TextureAgreement at_held = texture.agreement(prepared, held, scene.camera);
  EXPECT_LT(at_held.correlation, 0.3) << "the held pose agrees: the test shows nothing";
  // Steps of 1 cm, 5 each way: the truth is on the grid.
  const TextureShift best = texture.best_shift(prepared, held, scene.camera, 0.01, 5, 0.08);
  EXPECT_GE(best.agreement.points, SurfaceTexture::kMinPoints);
  // Tolerances: the truth is a grid point (the depth step is 8 % of the held depth, the offset
  // 8 % of the true one: 3 mm apart); a correlation near the unshifted one's (0.9+).
  EXPECT_GT(best.agreement.correlation, 0.8);
  EXPECT_LT(translation_error(best.object_to_camera, scene.start), 0.005);
  EXPECT_LT((best.shift_camera_m - (best.object_to_camera.translation() - held.translation())).norm(), 1e-12);
  // Nothing learned: nothing found.
  const SurfaceTexture untrained(scene.mesh);
  EXPECT_EQ(untrained.best_shift(prepared, held, scene.camera, 0.01, 5, 0.08).agreement.points, 0);
}

/// align(): the cube shown at its pose, the held pose turned 12 deg about an axis that is none
/// of the cube's (camera x and y mixed) and 1 cm to the side: no turn about the object's axes and
/// no shift alone matches; the local search over all six parameters does.
TEST(SurfaceTexture, AnAlignmentFindsTheSurfaceTurnedAboutAnyAxis) {
  const TextureScene scene;
  SurfaceTexture texture(scene.mesh);
  texture.learn(scene.frame(scene.start, 1), scene.start, scene.camera);
  ASSERT_TRUE(texture.ready());
  const Eigen::Vector3d center_camera = scene.start * Eigen::Vector3d::Zero();  // the box's centre
  Pose held = scene.start;
  held.linear() =
      Eigen::AngleAxisd(12.0 * M_PI / 180.0, Eigen::Vector3d(1.0, 1.0, 0.0).normalized())
          .toRotationMatrix() *
      scene.start.linear();
  held.translation() = center_camera + Eigen::Vector3d(0.01, 0.0, 0.0);
  const cv::Mat shown = scene.frame(scene.start, 2);
  const PreparedFrame prepared = texture.prepare(shown, held, scene.camera);
  const TextureAgreement at_held = texture.agreement(prepared, held, scene.camera);
  EXPECT_LT(at_held.correlation, 0.3) << "the held pose agrees: the test shows nothing";
  // Bounds 20 deg and 1.7 cm (a tenth of the cube's diameter), 300 agreements.
  const TextureAlignment aligned =
      texture.align(prepared, held, scene.camera, 20.0 * M_PI / 180.0, 0.017, 300);
  EXPECT_LE(aligned.evaluations, 300);
  // Tolerances: the learned points are 1 % of the object's size apart after smoothing (1.7 mm);
  // measured 0.9+ correlation at the truth.
  EXPECT_GT(aligned.agreement.correlation, 0.8);
  EXPECT_LT(rotation_error_deg(aligned.object_to_camera, scene.start), 2.0);
  EXPECT_LT(translation_error(aligned.object_to_camera, scene.start), 0.003);
  // Nothing learned, or no room to move: the given pose.
  const SurfaceTexture untrained(scene.mesh);
  const TextureAlignment none = untrained.align(prepared, held, scene.camera, 0.35, 0.017, 300);
  EXPECT_EQ(none.agreement.points, 0);
  EXPECT_TRUE(none.object_to_camera.isApprox(held));
  EXPECT_TRUE(
      texture.align(prepared, held, scene.camera, 0.0, 0.017, 300).object_to_camera.isApprox(held));
}

}  // namespace
}  // namespace kct
