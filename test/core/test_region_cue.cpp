#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "klt_contour_tracker/core/region_cue.h"
#include "klt_contour_tracker/core/renderer.h"
#include "klt_contour_tracker/core/visibility_table.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

/// An untextured box rendered over a uniform background of another colour (or of the same
/// colour), with the histograms learned at the true pose.
class RegionCueTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto mesh = std::make_shared<Mesh>(test::make_box(0.08, 0.06, 0.05, /*textured=*/false));
    mesh->base_color = cv::Vec3b(40, 60, 200);  // red-ish
    mesh_ = mesh;
    table_ = VisibilityTable::build(*mesh_, 3, 128, "");
  }
  static void TearDownTestSuite() {
    mesh_.reset();
    table_.reset();
  }

  void SetUp() override {
    extractor_ = std::make_shared<ContourExtractor>(mesh_, table_, 45.0);
    truth_ = test::make_pose(0.4);
    const Renderer renderer(mesh_);
    const cv::Mat background(camera_.size(), CV_8UC3, cv::Scalar(200, 120, 40));  // blue-ish
    frame_ = test::render_frame(renderer, camera_, truth_, background, 3.0);
    const cv::Mat mask = renderer.render(truth_, camera_).mask();
    ASSERT_TRUE(histograms_.learn(frame_, mask, 10, 1.0));
  }

  static std::shared_ptr<const Mesh> mesh_;
  static std::shared_ptr<const VisibilityTable> table_;
  std::shared_ptr<const ContourExtractor> extractor_;
  const PinholeCamera camera_ = test::make_camera();
  Pose truth_;
  cv::Mat frame_;
  ColorHistograms histograms_;
};
std::shared_ptr<const Mesh> RegionCueTest::mesh_;
std::shared_ptr<const VisibilityTable> RegionCueTest::table_;

/// The pose moved by an increment: rotation vector w about the object centre, then v (camera
/// frame), as the cue's gradient is defined.
Pose apply_increment(const Pose& pose, const Vector6d& delta, const Eigen::Vector3d& center) {
  const Eigen::Vector3d w = delta.head<3>();
  const Eigen::Matrix3d r = w.norm() > 0
                                ? Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix()
                                : Eigen::Matrix3d::Identity();
  const Eigen::Vector3d c = pose * center;
  Pose moved = Pose::Identity();
  moved.linear() = r * pose.linear();
  moved.translation() = r * (pose.translation() - c) + c + delta.tail<3>();
  return moved;
}

TEST_F(RegionCueTest, BestAtTheTruePose) {
  RegionCue cue(extractor_, RegionCueSettings{});
  const Eigen::Vector3d center = mesh_->bounding_box_center();
  cue.set_frame(frame_, histograms_, center);
  const double at_truth = cue.cost_at(truth_, camera_);
  EXPECT_GT(cue.line_count(), 40);
  // Clean colours: every line's most likely outline position is where it is (cost ~0: well
  // below a tenth of a px^2-weighted unit).
  EXPECT_GE(at_truth, 0.0);
  EXPECT_LT(at_truth, 0.1);
  // Every single-parameter offset (3 deg, 4 mm = ~6 px at 0.4 m) costs more, re-linearized at
  // the offset pose (a pure function of the pose) and with the lines of the true pose.
  cue.linearize(truth_, camera_);
  for (int i = 0; i < 6; ++i)
    for (double sign : {-1.0, 1.0}) {
      Vector6d x = Vector6d::Zero();
      x[i] = sign * (i < 3 ? 3.0 * M_PI / 180.0 : 0.004);
      const Pose moved = apply_increment(truth_, x, center);
      EXPECT_GT(cue.evaluate(moved, nullptr, nullptr), at_truth + 0.05) << "parameter " << i;
      RegionCue fresh(extractor_, RegionCueSettings{});
      fresh.set_frame(frame_, histograms_, center);
      EXPECT_GT(fresh.cost_at(moved, camera_), at_truth + 0.05) << "parameter " << i;
    }
}

TEST_F(RegionCueTest, AnalyticGradientMatchesFiniteDifferences) {
  RegionCue cue(extractor_, RegionCueSettings{});
  const Eigen::Vector3d center = mesh_->bounding_box_center();
  cue.set_frame(frame_, histograms_, center);
  // Lines placed 2 deg and 3 mm away from the truth, evaluated a bit further along.
  Vector6d x;
  x << 0.02, -0.015, 0.01, 0.003, -0.002, 0.004;
  cue.linearize(apply_increment(truth_, x, center), camera_);
  Vector6d y;
  y << 0.004, 0.002, -0.003, 0.001, 0.0005, -0.001;
  const Pose pose = apply_increment(apply_increment(truth_, x, center), y, center);
  Vector6d analytic = Vector6d::Zero();
  Eigen::Matrix<double, 6, 6> hessian = Eigen::Matrix<double, 6, 6>::Zero();
  const double value = cue.evaluate(pose, &analytic, &hessian);
  Vector6d numeric;
  for (int i = 0; i < 6; ++i) {
    const double h = i < 3 ? 1e-5 : 2e-6;
    Vector6d plus = Vector6d::Zero(), minus = Vector6d::Zero();
    plus[i] = h;
    minus[i] = -h;
    numeric[i] = (cue.evaluate(apply_increment(pose, plus, center), nullptr, nullptr) -
                  cue.evaluate(apply_increment(pose, minus, center), nullptr, nullptr)) /
                 (2 * h);
  }
  EXPECT_TRUE(std::isfinite(value));
  ASSERT_GT(numeric.norm(), 0.0);
  // Exact for the function evaluated (lines fixed): agreement to 1e-4 relative.
  EXPECT_LT((analytic - numeric).norm(), 1e-4 * numeric.norm())
      << "analytic " << analytic.transpose() << "\nnumeric " << numeric.transpose();
  // The Hessian approximation is symmetric positive semi-definite.
  EXPECT_LT((hessian - hessian.transpose()).norm(), 1e-12 * hessian.norm());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(hessian);
  EXPECT_GE(eigen.eigenvalues().minCoeff(), -1e-9 * eigen.eigenvalues().maxCoeff());
}

TEST_F(RegionCueTest, GaussNewtonStepsReturnToTheTruePose) {
  // Damped Newton steps with the cue's gradient and Hessian, re-linearized each step, from
  // 2-3 deg and 4-6 mm off: the cue alone brings the pose back.
  RegionCue cue(extractor_, RegionCueSettings{});
  const Eigen::Vector3d center = mesh_->bounding_box_center();
  cue.set_frame(frame_, histograms_, center);
  Vector6d x;
  x << 0.03, -0.02, 0.04, 0.004, 0.003, -0.006;
  Pose pose = apply_increment(truth_, x, center);
  for (int it = 0; it < 30; ++it) {
    const double scale = it < 10 ? 2.0 : 1.0;  // coarse then fine lines
    cue.linearize(pose, camera_, scale);
    Vector6d g = Vector6d::Zero();
    Eigen::Matrix<double, 6, 6> h = Eigen::Matrix<double, 6, 6>::Zero();
    cue.evaluate(pose, &g, &h);
    h.diagonal() += 1e-3 * h.diagonal().cwiseMax(1e-9) + Vector6d::Constant(1e-9);
    const Vector6d step = -h.ldlt().solve(g);
    pose = apply_increment(pose, step, center);
  }
  const Pose error = truth_.inverse() * pose;
  EXPECT_LT(Eigen::AngleAxisd(error.linear()).angle() * 180 / M_PI, 1.0);
  EXPECT_LT((pose.translation() - truth_.translation()).head<2>().norm(), 0.001);
  EXPECT_LT(std::abs(pose.translation().z() - truth_.translation().z()), 0.004);
}

TEST_F(RegionCueTest, FlatWhenTheBackgroundHasTheObjectsColours) {
  // Histograms learned with the same colours on both sides: every posterior is 0.5, the cue
  // carries no information and must not pull the pose anywhere.
  ColorHistograms uninformative;
  const cv::Mat mask = Renderer(mesh_).render(truth_, camera_).mask();
  const cv::Mat uniform(frame_.size(), CV_8UC3, cv::Scalar(40, 60, 200));
  ASSERT_TRUE(uninformative.learn(uniform, mask, 10, 1.0));
  RegionCue cue(extractor_, RegionCueSettings{});
  cue.set_frame(uniform, uninformative, mesh_->bounding_box_center());
  cue.linearize(truth_, camera_);
  Vector6d gradient = Vector6d::Zero();
  EXPECT_NEAR(cue.evaluate(truth_, &gradient, nullptr), 0.0, 1e-12);
  EXPECT_LT(gradient.norm(), 1e-12);
}

TEST_F(RegionCueTest, LinesOutsideTheImageWeighNothing) {
  RegionCue cue(extractor_, RegionCueSettings{});
  cue.set_frame(frame_, histograms_, mesh_->bounding_box_center());
  // Moved 0.5 m sideways: the whole outline leaves the image; every line is "unknown" and
  // weighs exactly 0, wherever the pose then moves.
  Pose away = truth_;
  away.translation().x() += 0.5;
  cue.linearize(away, camera_);
  EXPECT_GT(cue.line_count(), 40);
  Vector6d gradient = Vector6d::Zero();
  Vector6d step = Vector6d::Zero();
  step[3] = 0.01;
  EXPECT_EQ(
      cue.evaluate(apply_increment(away, step, mesh_->bounding_box_center()), &gradient, nullptr),
      0.0);
  EXPECT_EQ(gradient.norm(), 0.0);
}

/// A small box standing in front of a large one of the same colour: the small box's outline
/// lies inside the object's silhouette, object on both sides (as an arm before a body).
TEST(RegionCue, OnlyTheOuterOutlineCountsWithASilhouette) {
  auto mesh = std::make_shared<Mesh>();
  test::append_box(*mesh, {-0.05, -0.04, -0.03}, {0.05, 0.04, 0.0});     // back
  test::append_box(*mesh, {-0.015, -0.015, -0.06}, {0.015, 0.015, -0.03});  // front
  mesh->base_color = cv::Vec3b(40, 60, 200);
  const auto extractor = std::make_shared<ContourExtractor>(
      mesh, VisibilityTable::build(*mesh, 3, 128, ""), 45.0);
  const PinholeCamera camera = test::make_camera();
  const Pose truth = test::make_pose(0.4, 10, -10, 5);  // the front box faces the camera
  const Renderer renderer(mesh);
  const cv::Mat background(camera.size(), CV_8UC3, cv::Scalar(200, 120, 40));
  const cv::Mat frame = test::render_frame(renderer, camera, truth, background, 3.0);
  ColorHistograms histograms;
  ASSERT_TRUE(histograms.learn(frame, renderer.render(truth, camera).mask(), 10, 1.0));
  const Eigen::Vector3d center = mesh->bounding_box_center();
  const auto silhouette = [&](const Pose& pose) { return renderer.render(pose, camera).mask(); };

  RegionCue cue(extractor, RegionCueSettings{});
  cue.set_frame(frame, histograms, center);
  // Without the silhouette the front box's all-object lines each claim, confidently, that the
  // outline lies a line's length further out: far from the minimum at the truth.
  const double biased = cue.cost_at(truth, camera);
  const int all_lines = cue.line_count();
  EXPECT_GT(biased, 1.0);
  const double at_truth = cue.cost_at(truth, camera, 1.0, silhouette(truth));
  EXPECT_LT(cue.line_count(), all_lines);
  EXPECT_GT(cue.line_count(), 40);
  EXPECT_GE(at_truth, 0.0);
  EXPECT_LT(at_truth, 0.1);
  // Every single-parameter offset (3 deg, 4 mm) costs more.
  for (int i = 0; i < 6; ++i)
    for (double sign : {-1.0, 1.0}) {
      Vector6d x = Vector6d::Zero();
      x[i] = sign * (i < 3 ? 3.0 * M_PI / 180.0 : 0.004);
      const Pose moved = apply_increment(truth, x, center);
      EXPECT_GT(cue.cost_at(moved, camera, 1.0, silhouette(moved)), at_truth + 0.05)
          << "parameter " << i;
    }
  EXPECT_THROW(cue.linearize(truth, camera, 1.0, cv::Mat(10, 10, CV_8UC1)), std::invalid_argument);
}

TEST(RegionCue, RejectsBadSettings) {
  auto mesh = std::make_shared<const Mesh>(test::make_box(0.1, 0.1, 0.1, false));
  auto extractor = std::make_shared<const ContourExtractor>(mesh, nullptr, 45.0);
  RegionCueSettings s;
  EXPECT_THROW(RegionCue(nullptr, s), std::invalid_argument);
  s.line_half_length_px = 1;
  EXPECT_THROW(RegionCue(extractor, s), std::invalid_argument);
  s = RegionCueSettings{};
  s.step_amplitude = 0.5;
  EXPECT_THROW(RegionCue(extractor, s), std::invalid_argument);
  s = RegionCueSettings{};
  s.line_spacing_px = 0.0;
  EXPECT_THROW(RegionCue(extractor, s), std::invalid_argument);
  RegionCue cue(extractor, RegionCueSettings{});
  EXPECT_THROW(cue.linearize(Pose::Identity(), test::make_camera()), std::logic_error);
  EXPECT_NEAR(cue.evaluate(Pose::Identity(), nullptr, nullptr), 0.0, 0.0);  // no lines
}

}  // namespace
}  // namespace kct
