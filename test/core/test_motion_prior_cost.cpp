#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "klt_contour_tracker/core/motion_prior_cost.h"

namespace kct {
namespace {

const Eigen::Vector3d kCenter(0.02, -0.01, 0.03);

Pose predicted_pose() {
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, -1, 2).normalized()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.03, 0.01, 0.5);
  return pose;
}

Vector6d sigma() {
  Vector6d s;
  s << 0.05, 0.05, 0.1, 0.01, 0.01, 0.03;
  return s;
}

PoseCostFrame frame() {
  PoseCostFrame f;
  f.center_object = kCenter;
  return f;
}

TEST(MotionPriorCost, ZeroAtThePredictionHalfAtOneSigma) {
  MotionPriorCost cost;
  EXPECT_EQ(cost.name(), "motion");
  EXPECT_FALSE(cost.active());
  const PoseCostFrame f = frame();
  cost.begin_frame(f);
  cost.set_prediction(predicted_pose(), sigma());
  EXPECT_TRUE(cost.active());
  cost.linearize(predicted_pose(), 0);
  EXPECT_NEAR(cost.evaluate(predicted_pose(), nullptr, nullptr), 0.0, 1e-15);
  // One sigma on every axis at once: (1/12) * 6 = 0.5.
  const Pose one_sigma = apply_pose_increment(predicted_pose(), sigma(), kCenter);
  EXPECT_NEAR(cost.evaluate(one_sigma, nullptr, nullptr), 0.5, 1e-3);
  // Two sigma on one translation axis: 4 / 12.
  Vector6d two = Vector6d::Zero();
  two[4] = 2 * sigma()[4];
  EXPECT_NEAR(cost.evaluate(apply_pose_increment(predicted_pose(), two, kCenter), nullptr, nullptr),
              4.0 / 12.0, 1e-9);
  cost.clear();
  EXPECT_FALSE(cost.active());
}

TEST(MotionPriorCost, GradientAndHessian) {
  MotionPriorCost cost;
  const PoseCostFrame f = frame();
  cost.begin_frame(f);
  cost.set_prediction(predicted_pose(), sigma());
  Vector6d offset;
  offset << 0.02, -0.03, 0.05, 0.004, 0.006, -0.01;
  const Pose pose = apply_pose_increment(predicted_pose(), offset, kCenter);
  Vector6d analytic = Vector6d::Zero();
  Matrix6d hessian = Matrix6d::Zero();
  cost.evaluate(pose, &analytic, &hessian);
  Vector6d numeric;
  for (int i = 0; i < 6; ++i) {
    Vector6d h = Vector6d::Zero();
    h[i] = 1e-6;
    numeric[i] = (cost.evaluate(apply_pose_increment(pose, h, kCenter), nullptr, nullptr) -
                  cost.evaluate(apply_pose_increment(pose, -h, kCenter), nullptr, nullptr)) /
                 2e-6;
  }
  // First order in the error (rotation vectors do not add exactly): within 2 %.
  EXPECT_LT((analytic - numeric).norm(), 0.02 * numeric.norm()) << analytic.transpose() << "\n"
                                                                << numeric.transpose();
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(hessian(i, i), 1.0 / (6 * sigma()[i] * sigma()[i]), 1e-9);
  EXPECT_NEAR((hessian - Matrix6d(hessian.diagonal().asDiagonal())).norm(), 0.0, 0.0);
}

TEST(MotionPriorCost, RejectsBadSigma) {
  MotionPriorCost cost;
  Vector6d bad = sigma();
  bad[2] = 0.0;
  EXPECT_THROW(cost.set_prediction(predicted_pose(), bad), std::invalid_argument);
  bad[2] = std::nan("");
  EXPECT_THROW(cost.set_prediction(predicted_pose(), bad), std::invalid_argument);
  EXPECT_FALSE(cost.active());
}

}  // namespace
}  // namespace kct
