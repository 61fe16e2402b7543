// Pose covariance from keypoint residuals: agrees with the empirical scatter of PnP poses on
// noisy synthetic correspondences, shrinks with more points, REP 103 ordering (a lateral
// translation is better determined than depth), degenerate input; and the search-box fallback.
#include <gtest/gtest.h>

#include <random>

#include "klt_contour_tracker/core/pose_covariance.h"
// After Eigen (included above): OpenCV's Eigen bridge needs Eigen first.
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

namespace kct {
namespace {

PinholeCamera camera() { return PinholeCamera(600, 600, 320, 240, 640, 480); }

Pose truth() {
  Pose pose = Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.3, 1.0, 0.2).normalized()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.02, -0.01, 0.5);
  return pose;
}

std::vector<Eigen::Vector3d> object_points(int n, int seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.06, 0.06);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) points.emplace_back(u(rng), u(rng), u(rng));
  return points;
}

std::vector<Eigen::Vector2d> project(const std::vector<Eigen::Vector3d>& points, const Pose& pose,
                                     double noise_px, std::mt19937& rng) {
  std::normal_distribution<double> noise(0.0, noise_px);
  std::vector<Eigen::Vector2d> image;
  for (const auto& p : points)
    image.push_back(camera().project(pose * p) + Eigen::Vector2d(noise(rng), noise(rng)));
  return image;
}

// The pose perturbation of `estimate` relative to `reference` in the covariance's coordinates:
// dt, and dtheta with R_est = exp([dtheta]x) R_ref.
Eigen::Matrix<double, 6, 1> delta(const Pose& estimate, const Pose& reference) {
  Eigen::Matrix<double, 6, 1> d;
  d.head<3>() = estimate.translation() - reference.translation();
  const Eigen::AngleAxisd aa(estimate.linear() * reference.linear().transpose());
  d.tail<3>() = aa.angle() * aa.axis();
  return d;
}

TEST(PoseCovariance, MatchesTheScatterOfPnpPosesOnNoisyPoints) {
  const std::vector<Eigen::Vector3d> points = object_points(40, 1);
  const double noise_px = 1.0;
  std::mt19937 rng(5);
  std::vector<cv::Point3d> cv_points;
  for (const auto& p : points) cv_points.emplace_back(p.x(), p.y(), p.z());
  const int trials = 400;
  Matrix6d scatter = Matrix6d::Zero();
  Matrix6d predicted_sum = Matrix6d::Zero();
  for (int t = 0; t < trials; ++t) {
    const std::vector<Eigen::Vector2d> image = project(points, truth(), noise_px, rng);
    std::vector<cv::Point2d> cv_image;
    for (const auto& q : image) cv_image.emplace_back(q.x(), q.y());
    cv::Mat rvec, tvec;
    cv::eigen2cv(Eigen::Vector3d(Eigen::AngleAxisd(truth().linear()).angle() *
                                 Eigen::AngleAxisd(truth().linear()).axis()), rvec);
    cv::eigen2cv(Eigen::Vector3d(truth().translation()), tvec);
    cv::solvePnP(cv_points, cv_image, camera().K(), cv::noArray(), rvec, tvec, true,
                 cv::SOLVEPNP_ITERATIVE);
    Eigen::Vector3d r, tr;
    cv::cv2eigen(rvec, r);
    cv::cv2eigen(tvec, tr);
    Pose estimate = Pose::Identity();
    estimate.linear() = Eigen::AngleAxisd(r.norm(), r.normalized()).toRotationMatrix();
    estimate.translation() = tr;
    const Eigen::Matrix<double, 6, 1> d = delta(estimate, truth());
    scatter += d * d.transpose();
    const auto covariance = keypoint_pose_covariance(points, image, camera(), estimate, 0.0);
    ASSERT_TRUE(covariance);
    predicted_sum += *covariance;
  }
  scatter /= trials;
  const Matrix6d predicted = predicted_sum / trials;
  // Each standard deviation within 20% of the empirical one (400 trials: ~3.5% sampling error
  // on a standard deviation, plus the residual-based variance estimate's bias of 2N/(2N-6)).
  for (int i = 0; i < 6; ++i) {
    const double ratio = std::sqrt(predicted(i, i) / scatter(i, i));
    EXPECT_GT(ratio, 0.8) << "axis " << i;
    EXPECT_LT(ratio, 1.2) << "axis " << i;
  }
  // Depth (z) is the worst determined translation for a small object seen from 0.5 m.
  EXPECT_GT(predicted(2, 2), 10.0 * predicted(0, 0));
  EXPECT_GT(predicted(2, 2), 10.0 * predicted(1, 1));
  EXPECT_TRUE(predicted.isApprox(predicted.transpose(), 1e-12));
}

TEST(PoseCovariance, MorePointsAndTheSigmaFloor) {
  std::mt19937 rng(2);
  const auto few = object_points(8, 3), many = object_points(200, 3);
  const auto cov_few =
      keypoint_pose_covariance(few, project(few, truth(), 0.0, rng), camera(), truth(), 0.5);
  const auto cov_many =
      keypoint_pose_covariance(many, project(many, truth(), 0.0, rng), camera(), truth(), 0.5);
  ASSERT_TRUE(cov_few && cov_many);
  EXPECT_LT(cov_many->trace(), 0.5 * cov_few->trace());
  // Exact points: the floor decides; twice the floor = four times the covariance.
  const auto cov_floor2 =
      keypoint_pose_covariance(few, project(few, truth(), 0.0, rng), camera(), truth(), 1.0);
  ASSERT_TRUE(cov_floor2);
  EXPECT_NEAR(cov_floor2->trace() / cov_few->trace(), 4.0, 1e-9);
}

TEST(PoseCovariance, DegenerateInputGivesNothing) {
  std::mt19937 rng(2);
  const auto three = object_points(3, 4);
  EXPECT_FALSE(keypoint_pose_covariance(three, project(three, truth(), 0.0, rng), camera(), truth()));
  // All points identical: rank-deficient.
  const std::vector<Eigen::Vector3d> same(10, Eigen::Vector3d(0.01, 0.02, 0.0));
  EXPECT_FALSE(keypoint_pose_covariance(same, project(same, truth(), 0.0, rng), camera(), truth()));
  // Behind the camera.
  Pose behind = truth();
  behind.translation().z() = -0.5;
  const auto pts = object_points(10, 5);
  EXPECT_FALSE(keypoint_pose_covariance(pts, project(pts, truth(), 0.0, rng), camera(), behind));
  // Size mismatch.
  EXPECT_FALSE(keypoint_pose_covariance(pts, {}, camera(), truth()));
}

TEST(PoseCovariance, SearchBoxFallbackIsTheBoxAsTwoSigma) {
  TrackerParams params;
  params.extrapolated_lateral_bound = 0.1;
  params.extrapolated_axial_bound = 0.2;
  params.extrapolated_rotation_bound_deg = 30.0;
  const Matrix6d c = search_box_pose_covariance(0.2, params, 1.0);
  EXPECT_NEAR(std::sqrt(c(0, 0)), 0.01, 1e-12);
  EXPECT_NEAR(std::sqrt(c(1, 1)), 0.01, 1e-12);
  EXPECT_NEAR(std::sqrt(c(2, 2)), 0.02, 1e-12);
  for (int i = 3; i < 6; ++i) EXPECT_NEAR(std::sqrt(c(i, i)), 15.0 * M_PI / 180.0, 1e-12);
  EXPECT_EQ((c - Matrix6d(c.diagonal().asDiagonal())).norm(), 0.0);
  EXPECT_NEAR(search_box_pose_covariance(0.2, params, 4.0)(0, 0), 4.0 * c(0, 0), 1e-15);
  EXPECT_THROW(search_box_pose_covariance(0.0, params), std::invalid_argument);
  EXPECT_THROW(search_box_pose_covariance(0.2, params, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace kct
