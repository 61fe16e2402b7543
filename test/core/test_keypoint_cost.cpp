// The keypoint-reprojection cue: zero at the keypoints' pose, analytic gradient equal to the
// numeric one, Huber-bounded influence of an outlier, inactive without keypoints.
#include <gtest/gtest.h>

#include "klt_contour_tracker/core/keypoint_cost.h"
#include "klt_contour_tracker/core/keypoint_tracker.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

class KeypointCostTest : public ::testing::Test {
 protected:
  void SetUp() override {
    frame_.levels.resize(1);
    frame_.levels[0].camera = camera_;
    frame_.center_object = Eigen::Vector3d(0.01, 0.0, -0.01);
    keypoints_.success = true;
    cv::RNG rng(2);
    for (int i = 0; i < 30; ++i) {
      const Eigen::Vector3d p(rng.uniform(-0.06, 0.06), rng.uniform(-0.04, 0.04),
                              rng.uniform(-0.03, 0.03));
      keypoints_.inlier_points.points_object.push_back(p);
      keypoints_.inlier_points.points_image.push_back(camera_.project(truth_ * p));
    }
    frame_.keypoints = &keypoints_;
  }
  PinholeCamera camera_ = test::make_camera();
  Pose truth_ = test::make_pose(0.45);
  KeypointResult keypoints_;
  PoseCostFrame frame_;
};

TEST_F(KeypointCostTest, ZeroAtTheKeypointsPoseAndGradientMatchesNumeric) {
  KeypointCost cost(2.0, 4.0);
  cost.begin_frame(frame_);
  cost.linearize(truth_, 0);
  ASSERT_TRUE(cost.active());
  EXPECT_NEAR(cost.evaluate(truth_, nullptr, nullptr), 0.0, 1e-12);
  EXPECT_NEAR(cost.mean_error_px(truth_), 0.0, 1e-9);
  // Off by 1 deg and 3 mm: some residuals beyond the Huber threshold, some below.
  const Pose pose = test::move(truth_, 1.0, {0.3, 1.0, 0.2}, {0.003, 0.0, 0.0});
  Vector6d analytic = Vector6d::Zero();
  Matrix6d hessian = Matrix6d::Zero();
  const double value = cost.evaluate(pose, &analytic, &hessian);
  EXPECT_GT(value, 0.0);
  for (int i = 0; i < 6; ++i) {
    Vector6d d = Vector6d::Zero();
    d(i) = i < 3 ? 1e-6 : 1e-7;
    const double numeric =
        (cost.evaluate(apply_pose_increment(pose, d, frame_.center_object), nullptr, nullptr) -
         cost.evaluate(apply_pose_increment(pose, -d, frame_.center_object), nullptr, nullptr)) /
        (2 * d(i));
    // Tolerance: 1e-4 relative to the gradient's norm (central differences).
    EXPECT_NEAR(analytic(i), numeric, 1e-4 * analytic.norm()) << "parameter " << i;
  }
  // A Gauss-Newton step from there goes most of the way back.
  const Vector6d step = hessian.ldlt().solve(-analytic);
  const Pose stepped = apply_pose_increment(pose, step, frame_.center_object);
  EXPECT_LT(cost.mean_error_px(stepped), 0.3 * cost.mean_error_px(pose));
}

TEST_F(KeypointCostTest, AnOutlierHasBoundedInfluence) {
  keypoints_.inlier_points.points_image[0] += Eigen::Vector2d(300.0, 0.0);
  KeypointCost huber(2.0, 4.0), squared(2.0, 1e6);
  huber.begin_frame(frame_);
  huber.linearize(truth_, 0);
  squared.begin_frame(frame_);
  squared.linearize(truth_, 0);
  Vector6d g_huber = Vector6d::Zero(), g_squared = Vector6d::Zero();
  huber.evaluate(truth_, &g_huber, nullptr);
  squared.evaluate(truth_, &g_squared, nullptr);
  // The outlier's pull is k / |r| = 4 / 300 of its least-squares pull.
  EXPECT_NEAR(g_huber.norm() / g_squared.norm(), 4.0 / 300.0, 1e-6);
}

TEST_F(KeypointCostTest, InactiveWithoutKeypoints) {
  KeypointCost cost(2.0, 4.0);
  frame_.keypoints = nullptr;
  cost.begin_frame(frame_);
  cost.linearize(truth_, 0);
  EXPECT_FALSE(cost.active());
  EXPECT_EQ(cost.evaluate(truth_, nullptr, nullptr), 0.0);
  keypoints_.success = false;
  frame_.keypoints = &keypoints_;
  cost.begin_frame(frame_);
  cost.linearize(truth_, 0);
  EXPECT_FALSE(cost.active());
  EXPECT_THROW(KeypointCost(0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(KeypointCost(1.0, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace kct
