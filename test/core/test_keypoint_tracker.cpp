// KLT + PnP (paper Sec. 3.1): keypoints anchored on a rendered textured box recover a known
// motion between two rendered frames.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "klt_contour_tracker/core/keypoint_tracker.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

class KeypointTrackerTest : public ::testing::Test {
 protected:
  std::shared_ptr<const Mesh> mesh_ = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Renderer renderer_{mesh_};
  PinholeCamera camera_ = test::make_camera();
  cv::Mat background_ = test::make_background(camera_.size(), 11);
  TrackerParams params_;

  cv::Mat gray_at(const Pose& pose, int seed) {
    cv::Mat gray;
    cv::cvtColor(test::render_frame(renderer_, camera_, pose, background_, 2.0, seed), gray,
                 cv::COLOR_BGR2GRAY);
    return gray;
  }
};

TEST_F(KeypointTrackerTest, DetectedKeypointsAreAnchoredOnTheMeshSurface) {
  const Pose pose = test::make_pose(0.4);
  KeypointTracker tracker(mesh_, params_);
  const int detected = tracker.detect(gray_at(pose, 1), pose, camera_);
  ASSERT_GE(detected, 50) << "a textured box should give many corners";
  // Re-track on the same frame: every point is an inlier at the same pose with ~0 error.
  const KeypointResult same = tracker.track(gray_at(pose, 1), pose, camera_);
  ASSERT_TRUE(same.success);
  for (size_t i = 0; i < same.inlier_points.points_object.size(); ++i) {
    const Eigen::Vector3d p = same.inlier_points.points_object[i];
    // On the surface of the box: one coordinate sits on a face plane (tolerance 1e-4 m).
    const double on_face = std::min({std::abs(std::abs(p.x()) - 0.06), std::abs(std::abs(p.y()) - 0.04),
                                     std::abs(std::abs(p.z()) - 0.03)});
    EXPECT_LT(on_face, 1e-4) << "point " << p.transpose();
    // Reprojects where it was detected (tolerance 0.05 px).
    EXPECT_LT((camera_.project(pose * p) - same.inlier_points.points_image[i]).norm(), 0.05);
  }
}

TEST_F(KeypointTrackerTest, RecoversAKnownMotionBetweenRenderedFrames) {
  const Pose pose0 = test::make_pose(0.4);
  const Pose pose1 = test::move(pose0, 3.0, {0.3, 1.0, 0.2}, {0.006, -0.004, 0.01});
  KeypointTracker tracker(mesh_, params_);
  ASSERT_GE(tracker.detect(gray_at(pose0, 1), pose0, camera_), 50);
  const KeypointResult result = tracker.track(gray_at(pose1, 2), pose0, camera_);
  ASSERT_TRUE(result.success);
  EXPECT_GE(result.inlier_ratio, 0.8);
  // Tolerances: 1.5 mm and 0.3 deg at 0.4 m for a 12 cm box with 2-level sensor noise.
  EXPECT_LT(translation_error(result.object_to_camera, pose1), 0.0015);
  EXPECT_LT(rotation_error_deg(result.object_to_camera, pose1), 0.3);
  EXPECT_LT(result.mean_reprojection_px, 0.5);
}

TEST_F(KeypointTrackerTest, RejectsAPnpPoseThatMovedImplausiblyFarFromTheExpectedOne) {
  const Pose pose0 = test::make_pose(0.4);
  const Pose pose1 = test::move(pose0, 3.0, {0.3, 1.0, 0.2}, {0.006, -0.004, 0.01});
  const Eigen::Vector3d centre = mesh_->bounding_box_center();
  const double diameter = mesh_->diameter();
  // The same frames, but the caller expected the object 30 deg / 20 cm away from where the
  // keypoints put it: with the bounds on, the PnP pose is not used.
  const Pose far_expected = test::move(pose0, 30.0, {1.0, 0.0, 0.0}, {0.2, 0.0, 0.0});
  for (const bool bounded : {false, true}) {
    TrackerParams params = params_;
    if (bounded) {
      params.keypoint_max_motion_deg = 25.0;
      params.keypoint_max_motion_diameters = 0.5;
    }
    KeypointTracker tracker(mesh_, params);
    tracker.set_object_extent(diameter, centre);
    ASSERT_GE(tracker.detect(gray_at(pose0, 1), pose0, camera_), 50);
    const KeypointResult result = tracker.track(gray_at(pose1, 2), far_expected, camera_);
    EXPECT_EQ(result.implausible_motion, bounded);
    EXPECT_EQ(result.success, !bounded);
  }
  // Within the bounds (3 deg, ~1.3 cm): accepted as before.
  TrackerParams params = params_;
  params.keypoint_max_motion_deg = 25.0;
  params.keypoint_max_motion_diameters = 0.5;
  KeypointTracker tracker(mesh_, params);
  tracker.set_object_extent(diameter, centre);
  ASSERT_GE(tracker.detect(gray_at(pose0, 1), pose0, camera_), 50);
  const KeypointResult result = tracker.track(gray_at(pose1, 2), pose0, camera_);
  EXPECT_TRUE(result.success);
  EXPECT_FALSE(result.implausible_motion);
}

TEST_F(KeypointTrackerTest, FailsWithoutTextureAndAsksForRedetection) {
  auto plain = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06, /*textured=*/false));
  Renderer renderer(plain);
  // Uniform light: every face has the same grey, so the only image structure is the
  // silhouette, which the eroded detection mask excludes.
  RenderOptions uniform;
  uniform.ambient = 1.0;
  uniform.diffuse = 0.0;
  const Pose pose0 = test::make_pose(0.4);
  cv::Mat gray0, gray1;
  cv::cvtColor(test::render_frame(renderer, camera_, pose0, background_, 0.0, 3, uniform), gray0, cv::COLOR_BGR2GRAY);
  const Pose pose1 = test::move(pose0, 2.0, {0, 1, 0}, {0.005, 0, 0});
  cv::cvtColor(test::render_frame(renderer, camera_, pose1, background_, 0.0, 3, uniform), gray1, cv::COLOR_BGR2GRAY);
  KeypointTracker tracker(plain, params_);
  tracker.detect(gray0, pose0, camera_);
  const KeypointResult result = tracker.track(gray1, pose0, camera_);
  EXPECT_FALSE(result.success);
  EXPECT_LT(result.tracked, params_.klt_min_points);
  EXPECT_TRUE(tracker.needs_redetection());
}

TEST_F(KeypointTrackerTest, NoKeypointsWhenTheObjectIsOutOfView) {
  Pose behind = test::make_pose(0.4);
  behind.translation().x() = 5.0;  // far to the side: not in the image
  KeypointTracker tracker(mesh_, params_);
  EXPECT_EQ(tracker.detect(gray_at(test::make_pose(0.4), 1), behind, camera_), 0);
  EXPECT_FALSE(tracker.track(gray_at(test::make_pose(0.4), 2), behind, camera_).success);
}

TEST(RefinedPoseAgreement, AcceptsPosesTheKeypointsAgreeWithAndRejectsOthers) {
  const PinholeCamera camera = test::make_camera();
  const Pose pnp = test::make_pose(0.45);
  KeypointResult keypoints;
  keypoints.success = true;
  keypoints.object_to_camera = pnp;
  const Mesh box = test::make_box(0.12, 0.08, 0.06);
  for (const Eigen::Vector3d& v : box.vertices) {
    keypoints.inlier_points.points_object.push_back(v);
    keypoints.inlier_points.points_image.push_back(camera.project(pnp * v));
  }
  // 0.05 deg moves the box's corners by well under 0.5 px; 3 deg by several px.
  EXPECT_TRUE(refined_pose_agrees_with_keypoints(keypoints, test::move(pnp, 0.05, {0, 1, 0}, {0, 0, 0}),
                                                 camera, 0.5));
  EXPECT_FALSE(refined_pose_agrees_with_keypoints(keypoints, test::move(pnp, 3.0, {0, 1, 0}, {0, 0, 0}),
                                                  camera, 0.5));
  // Without KLT there is nothing to disagree with.
  keypoints.success = false;
  EXPECT_TRUE(refined_pose_agrees_with_keypoints(keypoints, test::move(pnp, 3.0, {0, 1, 0}, {0, 0, 0}),
                                                 camera, 0.5));
}

}  // namespace
}  // namespace kct
