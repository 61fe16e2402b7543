// Metrics of the paper's Sec. 4.1 on hand-made inputs with known answers.
#include <gtest/gtest.h>

#include "klt_contour_tracker/core/metrics.h"

namespace kct {
namespace {

TEST(Metrics, MeanVertexDistanceOfAPureTranslationIsItsLength) {
  const std::vector<Eigen::Vector3d> vertices{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  Pose truth = Pose::Identity();
  Pose estimated = Pose::Identity();
  estimated.translation() = Eigen::Vector3d(0.03, 0.04, 0.0);
  EXPECT_NEAR(mean_vertex_distance(vertices, estimated, truth), 0.05, 1e-12);
}

TEST(Metrics, MeanVertexDistanceOfARotation) {
  // 180 deg about z: (1,0,0) -> (-1,0,0) is 2 away, (0,1,0) -> 2 away, origin stays.
  const std::vector<Eigen::Vector3d> vertices{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  Pose estimated = Pose::Identity();
  estimated.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(mean_vertex_distance(vertices, estimated, Pose::Identity()), 4.0 / 3.0, 1e-12);
}

TEST(Metrics, AucIsTwentyForPerfectTracking) {
  EXPECT_NEAR(auc_score({0.0, 0.0, 0.0}, 1.0), 20.0, 1e-12);
}

TEST(Metrics, AucIsZeroWhenEveryErrorExceedsTheRange) {
  EXPECT_NEAR(auc_score({0.2, 0.5, 3.0}, 1.0), 0.0, 1e-12);
}

TEST(Metrics, AucOfKnownErrors) {
  // Diameter 2: delta/d = 0.05 and 0.15. Success is 0 below k=0.05, 50% on [0.05, 0.15),
  // 100% on [0.15, 0.2]: area = 0.1 * 50 + 0.05 * 100 = 10.
  EXPECT_NEAR(auc_score({0.1, 0.3}, 2.0), 10.0, 1e-9);
}

TEST(Metrics, AucMatchesNumericIntegrationOfTheSuccessCurve) {
  const std::vector<double> deltas{0.01, 0.02, 0.05, 0.11, 0.19, 0.3, 0.004};
  const double diameter = 1.0;
  double numeric = 0.0;
  const int steps = 200000;
  for (int i = 0; i < steps; ++i) {
    const double k = (i + 0.5) * 0.2 / steps;
    numeric += 100.0 * success_rate(deltas, diameter, k) * 0.2 / steps;
  }
  EXPECT_NEAR(auc_score(deltas, diameter), numeric, 1e-3);
}

TEST(Metrics, AucRejectsANonPositiveDiameter) {
  EXPECT_THROW(auc_score({0.1}, 0.0), std::invalid_argument);
}

TEST(Metrics, SuccessFiveCentimetresFiveDegrees) {
  Pose ok = Pose::Identity();
  ok.translation() = Eigen::Vector3d(0.049, 0, 0);
  Pose far = Pose::Identity();
  far.translation() = Eigen::Vector3d(0.051, 0, 0);
  Pose turned = Pose::Identity();
  turned.linear() = Eigen::AngleAxisd(6.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const std::vector<Pose> truth(4, Pose::Identity());
  EXPECT_NEAR(success_translation_rotation({ok, far, turned, Pose::Identity()}, truth, 0.05, 5.0),
              0.5, 1e-12);
}

TEST(Metrics, Median) {
  EXPECT_DOUBLE_EQ(median({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(median({4, 1, 3, 2}), 2.5);
  EXPECT_DOUBLE_EQ(median({}), 0.0);
}

TEST(Metrics, NearestRankPercentile) {
  const std::vector<double> ten = {10, 1, 9, 2, 8, 3, 7, 4, 6, 5};
  EXPECT_DOUBLE_EQ(percentile(ten, 90), 9.0);
  EXPECT_DOUBLE_EQ(percentile(ten, 91), 10.0);
  EXPECT_DOUBLE_EQ(percentile(ten, 100), 10.0);
  EXPECT_DOUBLE_EQ(percentile(ten, 50), 5.0);
  EXPECT_DOUBLE_EQ(percentile(ten, 0), 1.0);
  EXPECT_DOUBLE_EQ(percentile({42}, 90), 42.0);
  EXPECT_DOUBLE_EQ(percentile({}, 90), 0.0);
}

TEST(Pose, ExtrapolationRepeatsTheLastMotion) {
  Pose p0 = Pose::Identity();
  p0.translation() = Eigen::Vector3d(0, 0, 0.5);
  Pose motion = Pose::Identity();
  motion.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d(0, 1, 0)).toRotationMatrix();
  motion.translation() = Eigen::Vector3d(0.01, -0.02, 0.005);
  const Pose p1 = motion * p0;
  const Pose p2 = extrapolate_pose(p0, p1);
  const Pose expected = motion * p1;
  EXPECT_LT(translation_error(p2, expected), 1e-12);
  EXPECT_LT(rotation_error_deg(p2, expected), 1e-6);
}

TEST(Pose, RowRoundTripAndValidity) {
  const Pose p = pose_from_quaternion(0.1, 0.2, 0.3, 0.1, 0.2, 0.3, 0.9);
  const Pose q = pose_from_row(pose_to_row(p));
  EXPECT_LT((p.matrix() - q.matrix()).norm(), 1e-12);
  EXPECT_TRUE(is_valid_pose(p));
  Pose bad = p;
  bad.translation().x() = std::nan("");
  EXPECT_FALSE(is_valid_pose(bad));
}

}  // namespace
}  // namespace kct
