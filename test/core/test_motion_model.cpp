#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "klt_contour_tracker/core/motion_model.h"

namespace kct {
namespace {

const Eigen::Vector3d kCenter(0.01, -0.02, 0.03);
constexpr double kSize = 0.2;

Pose start_pose() {
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.05, -0.02, 0.6);
  return pose;
}

double rotation_deg(const Pose& a, const Pose& b) {
  return Eigen::AngleAxisd(Eigen::Matrix3d(a.linear() * b.linear().transpose())).angle() * 180 /
         M_PI;
}

TEST(MotionIncrement, BetweenInvertsApply) {
  Vector6d delta;
  delta << 0.1, -0.05, 0.2, 0.03, -0.01, 0.02;
  const Pose from = start_pose();
  const Pose to = apply_pose_increment(from, delta, kCenter);
  EXPECT_TRUE(motion_increment_between(from, to, kCenter).isApprox(delta, 1e-12));
  // The rotation part turns about the centre: the centre moves by v only.
  EXPECT_TRUE((to * kCenter - from * kCenter).isApprox(delta.tail<3>(), 1e-12));
  EXPECT_TRUE(apply_pose_increment(from, Vector6d::Zero(), kCenter).isApprox(from));
}

TEST(MotionModel, PredictsConstantVelocity) {
  MotionModel model(kCenter, kSize);
  EXPECT_FALSE(model.initialized());
  Vector6d step;
  step << 0.02, 0.1, -0.03, 0.03, 0.0, -0.01;  // ~6 deg and 32 mm a frame (fast hand-held)
  Pose pose = start_pose();
  model.update(pose);  // acts as reset
  EXPECT_TRUE(model.initialized());
  EXPECT_TRUE(model.predict().isApprox(pose));  // no velocity yet
  const Vector6d initial_sigma = model.sigma();
  EXPECT_NEAR(initial_sigma[0], 8.0 * M_PI / 180, 1e-12);
  EXPECT_NEAR(initial_sigma[3], 0.2 * kSize, 1e-12);
  for (int k = 0; k < 25; ++k) {
    pose = apply_pose_increment(pose, step, kCenter);
    model.update(pose);
  }
  const Pose next = apply_pose_increment(pose, step, kCenter);
  // The smoothed velocity converged: the next pose is predicted within 0.01 deg / 0.1 mm, and
  // the uncertainty shrank to its floors (0.5 deg, 1 % of the size).
  EXPECT_LT(rotation_deg(model.predict(), next), 0.01);
  EXPECT_LT((model.predict().translation() - next.translation()).norm(), 1e-4);
  EXPECT_NEAR(model.sigma()[1], 0.5 * M_PI / 180, 1e-6);
  EXPECT_NEAR(model.sigma()[4], 0.01 * kSize, 1e-6);
  // The last pose alone (the paper without KLT extrapolates from two poses) is 6 deg off.
  EXPECT_GT(rotation_deg(pose, next), 5.0);
}

TEST(MotionModel, UncertaintyFollowsTheJitter) {
  // Zero mean velocity with 10 mm / 3 deg Gaussian jitter per frame and per axis: the learned
  // sigma is of that size (with velocity_smoothing 0.5 and error_smoothing 0.3 the prediction
  // error of such a random walk is 1.73 times the jitter on average: simulated).
  MotionModel model(kCenter, kSize);
  std::mt19937 rng(4);
  std::normal_distribution<double> rotation(0.0, 3.0 * M_PI / 180), translation(0.0, 0.01);
  Pose pose = start_pose();
  model.reset(pose);
  Vector6d sum = Vector6d::Zero();
  int count = 0;
  for (int k = 0; k < 400; ++k) {
    Vector6d jitter;
    jitter << rotation(rng), rotation(rng), rotation(rng), translation(rng), translation(rng),
        translation(rng);
    pose = apply_pose_increment(start_pose(), jitter, kCenter);
    model.update(pose);
    if (k > 50) {
      sum += model.sigma();
      ++count;
    }
  }
  const Vector6d mean = sum / count;
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(mean[i] * 180 / M_PI, 3.0 * 1.73, 0.8) << i;
  for (int i = 3; i < 6; ++i) EXPECT_NEAR(mean[i], 0.01 * 1.73, 0.003) << i;
}

TEST(MotionModel, CoastingMovesOnAndGrowsTheUncertainty) {
  MotionModel model(kCenter, kSize);
  Vector6d step = Vector6d::Zero();
  step[3] = 0.01;
  Pose pose = start_pose();
  model.reset(pose);
  for (int k = 0; k < 20; ++k) model.update(pose = apply_pose_increment(pose, step, kCenter));
  const Vector6d before = model.sigma();
  model.coast();  // a frame without a trusted pose
  EXPECT_NEAR((model.last_pose() * kCenter - pose * kCenter).x(), 0.01, 1e-6);
  EXPECT_NEAR(model.predict().translation().x() - pose.translation().x(), 0.02, 1e-6);
  model.coast();
  model.coast();
  for (int i = 0; i < 6; ++i) EXPECT_GE(model.sigma()[i], before[i]);
  // Reset forgets the velocity.
  model.reset(pose);
  EXPECT_TRUE(model.predict().isApprox(pose));
}

TEST(MotionModel, RejectsBadSettings) {
  EXPECT_THROW(MotionModel(kCenter, 0.0), std::invalid_argument);
  MotionModelSettings s;
  s.velocity_smoothing = 0.0;
  EXPECT_THROW(MotionModel(kCenter, kSize, s), std::invalid_argument);
  s = MotionModelSettings{};
  s.error_smoothing = 1.5;
  EXPECT_THROW(MotionModel(kCenter, kSize, s), std::invalid_argument);
  s = MotionModelSettings{};
  s.min_translation_sigma = -1;
  EXPECT_THROW(MotionModel(kCenter, kSize, s), std::invalid_argument);
}

}  // namespace
}  // namespace kct
