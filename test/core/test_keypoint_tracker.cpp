// KLT + PnP (paper Sec. 3.1): keypoints anchored on a rendered textured box recover a known
// motion between two rendered frames.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "klt_contour_tracker/core/keypoint_tracker.h"
#include "klt_contour_tracker/core/pose_cv.h"
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

TEST_F(KeypointTrackerTest, FallsBackToFaintCornersWhenTheStrongOnesAreFew) {
  // The box's texture faded to 20 % of its contrast and one black-and-white checker on it:
  // relative to the checker's corners the texture's are below corner_quality_level (an
  // untextured object whose only strong corners are a few edges), so few corners pass it.
  const Pose pose = test::make_pose(0.4);
  cv::Mat gray = gray_at(pose, 1);
  const cv::Mat inside = renderer_.render(pose, camera_).mask();
  const double mean = cv::mean(gray, inside)[0];
  cv::Mat faded;
  gray.convertTo(faded, CV_8U, 0.2, 0.8 * mean);
  faded.copyTo(gray, inside);
  const Eigen::Vector2d centre = camera_.project(pose * mesh_->bounding_box_center());
  for (int row = 0; row < 2; ++row)
    for (int col = 0; col < 2; ++col)
      cv::rectangle(gray, cv::Rect(static_cast<int>(centre.x()) - 8 + 8 * col,
                                   static_cast<int>(centre.y()) - 8 + 8 * row, 8, 8),
                    cv::Scalar((row + col) % 2 ? 255 : 0), cv::FILLED);
  KeypointTracker strict(mesh_, params_);
  const int strong = strict.detect(gray, pose, camera_);
  EXPECT_LT(strong, 30) << "the faded texture's corners should fall below the quality level";
  TrackerParams params = params_;
  params.corner_fallback_below = 30;
  KeypointTracker tracker(mesh_, params);
  const int detected = tracker.detect(gray, pose, camera_);
  EXPECT_GE(detected, 3 * std::max(strong, 10)) << "the fallback should find the faint corners";
  // They are anchored like any other: re-tracked on the same frame, all inliers at ~0 error
  // (tolerance 0.1 px: faint corners localize less sharply).
  const KeypointResult same = tracker.track(gray, pose, camera_);
  ASSERT_TRUE(same.success);
  EXPECT_LT(same.mean_reprojection_px, 0.1);
  EXPECT_GE(same.inlier_ratio, 0.95);
  // Enough corners at the quality level: the fallback changes nothing.
  KeypointTracker textured(mesh_, params);
  EXPECT_EQ(textured.detect(gray_at(pose, 1), pose, camera_),
            KeypointTracker(mesh_, params_).detect(gray_at(pose, 1), pose, camera_));
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

/// PnP (OpenCV, iterative, from `start`) on the points' projections at `truth` plus Gaussian
/// noise of `sigma_px`; also returns the noisy image points.
Pose noisy_pnp(const std::vector<Eigen::Vector3d>& points_object, const Pose& truth,
               const Pose& start, const PinholeCamera& camera, double sigma_px,
               std::vector<Eigen::Vector2d>& points_image) {
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, sigma_px);
  std::vector<cv::Point3f> object;
  std::vector<cv::Point2f> image;
  points_image.clear();
  for (const Eigen::Vector3d& p : points_object) {
    const Eigen::Vector2d uv = camera.project(truth * p) + Eigen::Vector2d(noise(rng), noise(rng));
    points_image.push_back(uv);
    object.emplace_back(p.x(), p.y(), p.z());
    image.emplace_back(uv.x(), uv.y());
  }
  cv::Mat rvec, tvec;
  pose_to_rvec_tvec(start, rvec, tvec);
  cv::solvePnP(object, image, camera.K(), cv::noArray(), rvec, tvec, true, cv::SOLVEPNP_ITERATIVE);
  return pose_from_rvec_tvec(rvec, tvec);
}

double angle_deg(const Pose& a, const Pose& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle() * 180.0 / M_PI;
}

TEST(PoseWithMotionPrior, KeepsWhatSpreadPointsFix) {
  // 60 points through a 12 x 8 x 6 cm volume, 0.7 px noise: the prior (5 deg, 15 mm) centred
  // 3 deg and 20 mm away from the truth moves the PnP pose by under 0.2 deg and 1 mm.
  const PinholeCamera camera = test::make_camera();
  const Pose truth = test::make_pose(0.45);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 60; ++i) points.emplace_back(0.06 * u(rng), 0.04 * u(rng), 0.03 * u(rng));
  std::vector<Eigen::Vector2d> image;
  const Pose pnp = noisy_pnp(points, truth, truth, camera, 0.7, image);
  const Pose expected = test::move(truth, 3.0, {1, 1, 0}, {0.012, 0.0, 0.016});
  const Pose map = pose_with_motion_prior(points, image, camera, pnp, expected, Eigen::Vector3d::Zero(),
                                          5.0 * M_PI / 180.0, 0.015);
  EXPECT_LT(angle_deg(map, pnp), 0.2);
  EXPECT_LT((map.translation() - pnp.translation()).norm(), 0.001);
}

TEST(PoseWithMotionPrior, HoldsWhatAStripOfPointsLeavesFree) {
  // 12 points in a 2 x 30 mm strip, 1.5 px noise (a blurred can's keypoints after a jerk): PnP
  // from a start
  // 40 mm too close drifts along what the strip leaves free; with the prior centred on the last
  // pose (here the truth, the object did not move) its errors shrink (22 -> 11 mm, the rotation
  // likewise), still fitting the points.
  const PinholeCamera camera = test::make_camera();
  const Pose truth = test::make_pose(0.45);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 12; ++i) points.emplace_back(i % 2 ? 0.001 : -0.001, -0.015 + 0.0027 * i, 0.0);
  std::vector<Eigen::Vector2d> image;
  const Pose start = test::move(truth, 6.0, {0, 1, 0}, {0.0, 0.0, -0.04});
  const Pose pnp = noisy_pnp(points, truth, start, camera, 1.5, image);
  const double pnp_error_m = (pnp.translation() - truth.translation()).norm();
  ASSERT_GT(pnp_error_m, 0.01) << "the scenario: PnP alone is off";
  const Pose map = pose_with_motion_prior(points, image, camera, pnp, truth, Eigen::Vector3d::Zero(),
                                          5.0 * M_PI / 180.0, 0.015);
  EXPECT_LT((map.translation() - truth.translation()).norm(), 0.6 * pnp_error_m);
  EXPECT_LT(angle_deg(map, truth), 0.6 * angle_deg(pnp, truth));
  double squared = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i)
    squared += (camera.project(map * points[i]) - image[i]).squaredNorm();
  EXPECT_LT(std::sqrt(squared / points.size()), 3.0);
}

}  // namespace
}  // namespace kct
