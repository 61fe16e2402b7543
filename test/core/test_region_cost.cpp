#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "klt_contour_tracker/core/region_cost.h"
#include "klt_contour_tracker/core/visibility_table.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

/// Levenberg-Marquardt on the cue alone from `pose` (damping relative to diag(H), adapted),
/// 10 steps on level 2, then 1, then 0.
Pose levenberg_marquardt(RegionCost& cost, Pose pose, const Eigen::Vector3d& center_object) {
  double lambda = 1.0;
  for (int level = 2; level >= 0; --level)
    for (int it = 0; it < 10; ++it) {
      cost.linearize(pose, level);
      Vector6d g = Vector6d::Zero();
      Matrix6d h = Matrix6d::Zero();
      const double before = cost.evaluate(pose, &g, &h);
      h.diagonal() += lambda * h.diagonal() + Vector6d::Constant(1e-12);
      const Pose candidate = apply_pose_increment(pose, -h.ldlt().solve(g), center_object);
      if (cost.evaluate(candidate, nullptr, nullptr) < before) {
        pose = candidate;
        lambda = std::max(1e-3, 0.3 * lambda);
      } else {
        lambda *= 10.0;
      }
    }
  return pose;
}

/// An untextured box over a background of other colours, frames as the refiner builds them.
class RegionCostTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto mesh = std::make_shared<Mesh>(test::make_box(0.08, 0.06, 0.05, /*textured=*/false));
    mesh->base_color = cv::Vec3b(40, 60, 200);
    mesh_ = mesh;
    extractor_ =
        std::make_shared<ContourExtractor>(mesh_, VisibilityTable::build(*mesh_, 3, 128, ""), 45.0);
    truth_ = test::make_pose(0.4);
    const Renderer renderer(mesh_);
    // Background: blue-ish cells of random brightness (clutter, but not of the object's hue).
    cv::Mat background = test::make_background(camera_.size(), 9, 16, 40, 200);
    std::vector<cv::Mat> channels;
    cv::split(background, channels);
    channels[2] *= 0.3;  // little red
    cv::merge(channels, background);
    bgr_ = test::render_frame(renderer, camera_, truth_, background, 3.0);
    cv::cvtColor(bgr_, gray_, cv::COLOR_BGR2GRAY);
    frame_.levels = make_pyramid(gray_, camera_, 3);
    frame_.bgr = bgr_;
    frame_.center_object = mesh_->bounding_box_center();
    frame_.predicted_object_to_camera = frame_.preliminary_object_to_camera = truth_;
  }

  std::shared_ptr<const Mesh> mesh_;
  std::shared_ptr<const ContourExtractor> extractor_;
  const PinholeCamera camera_ = test::make_camera();
  Pose truth_;
  cv::Mat bgr_, gray_;
  PoseCostFrame frame_;
};

TEST_F(RegionCostTest, InactiveUntilTheColoursAreLearned) {
  RegionCost cost(extractor_, RegionCueSettings{}, 10, 0.2);
  EXPECT_EQ(cost.name(), "region");
  cost.begin_frame(frame_);
  cost.linearize(truth_, 0);
  EXPECT_FALSE(cost.active());
  EXPECT_DOUBLE_EQ(cost.evaluate(truth_, nullptr, nullptr), 0.0);
  ASSERT_TRUE(cost.learn(bgr_, truth_, camera_));
  EXPECT_TRUE(cost.histograms().ready());
  // Learning from a given silhouette is the same as rendering it.
  RegionCost with_mask(extractor_, RegionCueSettings{}, 10, 0.2);
  ASSERT_TRUE(with_mask.learn(bgr_, Renderer(mesh_).render(truth_, camera_).mask()));
  EXPECT_EQ(with_mask.histograms().foreground(), cost.histograms().foreground());
  EXPECT_FALSE(with_mask.learn(bgr_, cv::Mat()));
  // A grey frame (no colour): inactive, whatever was learned.
  PoseCostFrame grey = frame_;
  grey.bgr = cv::Mat();
  cost.begin_frame(grey);
  cost.linearize(truth_, 0);
  EXPECT_FALSE(cost.active());
  EXPECT_FALSE(cost.learn(gray_, truth_, camera_));
  cost.begin_frame(frame_);
  cost.linearize(truth_, 0);
  EXPECT_TRUE(cost.active());
  EXPECT_LT(cost.evaluate(truth_, nullptr, nullptr), 0.1);
  Vector6d offset = Vector6d::Zero();
  offset[3] = 0.004;  // ~6 px
  EXPECT_GT(
      cost.evaluate(apply_pose_increment(truth_, offset, frame_.center_object), nullptr, nullptr),
      1.0);
  cost.forget();
  cost.begin_frame(frame_);
  cost.linearize(truth_, 0);
  EXPECT_FALSE(cost.active());
}

TEST_F(RegionCostTest, GradientMatchesFiniteDifferencesOnEveryLevel) {
  RegionCost cost(extractor_, RegionCueSettings{}, 10, 0.2);
  ASSERT_TRUE(cost.learn(bgr_, truth_, camera_));
  cost.begin_frame(frame_);
  Vector6d offset;
  offset << 0.03, -0.02, 0.02, 0.004, -0.003, 0.006;
  const Pose pose = apply_pose_increment(truth_, offset, frame_.center_object);
  for (int level = 0; level < 3; ++level) {
    cost.linearize(pose, level);
    Vector6d analytic = Vector6d::Zero();
    Matrix6d hessian = Matrix6d::Zero();
    cost.evaluate(pose, &analytic, &hessian);
    Vector6d numeric;
    for (int i = 0; i < 6; ++i) {
      Vector6d h = Vector6d::Zero();
      h[i] = i < 3 ? 1e-5 : 2e-6;
      numeric[i] =
          (cost.evaluate(apply_pose_increment(pose, h, frame_.center_object), nullptr, nullptr) -
           cost.evaluate(apply_pose_increment(pose, -h, frame_.center_object), nullptr, nullptr)) /
          (2 * h[i]);
    }
    ASSERT_GT(numeric.norm(), 0.0) << level;
    EXPECT_LT((analytic - numeric).norm(), 1e-4 * numeric.norm()) << "level " << level;
    EXPECT_GT(hessian.trace(), 0.0);
  }
}

TEST_F(RegionCostTest, CoarseToFineLevenbergMarquardtRecoversAFastMove) {
  // 6 deg and 15 mm (~22 px) off, as after a fast hand-held move: Levenberg-Marquardt steps
  // (damping relative to diag(H), adapted) on the region cue alone, level 2 then 1 then 0,
  // land within 1 deg and 2 mm (depth 5 mm). The damping matters: a silhouette constrains
  // some rotations weakly, and undamped Gauss-Newton steps on the cue alone wander off.
  RegionCost cost(extractor_, RegionCueSettings{}, 10, 0.2);
  ASSERT_TRUE(cost.learn(bgr_, truth_, camera_));
  cost.begin_frame(frame_);
  Vector6d offset;
  offset << 0.06, -0.05, 0.08, 0.015, -0.01, 0.0;
  const Pose pose = levenberg_marquardt(
      cost, apply_pose_increment(truth_, offset, frame_.center_object), frame_.center_object);
  const Pose error = truth_.inverse() * pose;
  EXPECT_LT(Eigen::AngleAxisd(error.linear()).angle() * 180 / M_PI, 1.0);
  EXPECT_LT((pose.translation() - truth_.translation()).head<2>().norm(), 0.002);
  EXPECT_LT(std::abs(pose.translation().z() - truth_.translation().z()), 0.005);
}

TEST(RegionCost, StaysAtTheTruePoseOfAnObjectWithInnerOutlines) {
  // A small box before a large one of the same colour: the small box's outline is inside the
  // silhouette. Levenberg-Marquardt on the region cue alone, started at the true pose, stays
  // there (within 0.5 deg and 1 mm): only the outer outline's lines count.
  auto mesh = std::make_shared<Mesh>();
  test::append_box(*mesh, {-0.05, -0.04, -0.03}, {0.05, 0.04, 0.0});
  test::append_box(*mesh, {-0.015, -0.015, -0.06}, {0.015, 0.015, -0.03});
  mesh->base_color = cv::Vec3b(40, 60, 200);
  const auto extractor = std::make_shared<ContourExtractor>(
      mesh, VisibilityTable::build(*mesh, 3, 128, ""), 45.0);
  const PinholeCamera camera = test::make_camera();
  const Pose truth = test::make_pose(0.4, 10, -10, 5);
  const Renderer renderer(mesh);
  const cv::Mat bgr = test::render_frame(
      renderer, camera, truth, cv::Mat(camera.size(), CV_8UC3, cv::Scalar(200, 120, 40)), 3.0);
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  PoseCostFrame frame;
  frame.levels = make_pyramid(gray, camera, 3);
  frame.bgr = bgr;
  frame.center_object = mesh->bounding_box_center();
  frame.predicted_object_to_camera = frame.preliminary_object_to_camera = truth;
  RegionCost cost(extractor, RegionCueSettings{}, 10, 0.2);
  ASSERT_TRUE(cost.learn(bgr, truth, camera));
  cost.begin_frame(frame);
  const Pose pose = levenberg_marquardt(cost, truth, frame.center_object);
  const Pose error = truth.inverse() * pose;
  EXPECT_LT(Eigen::AngleAxisd(error.linear()).angle() * 180 / M_PI, 0.5);
  EXPECT_LT((pose.translation() - truth.translation()).norm(), 0.001);
}

TEST(RegionCost, RejectsBadSettings) {
  auto mesh = std::make_shared<const Mesh>(test::make_box(0.1, 0.1, 0.1, false));
  auto extractor = std::make_shared<const ContourExtractor>(mesh, nullptr, 45.0);
  EXPECT_THROW(RegionCost(extractor, RegionCueSettings{}, 0, 0.2), std::invalid_argument);
  EXPECT_THROW(RegionCost(extractor, RegionCueSettings{}, 10, 0.0), std::invalid_argument);
  RegionCueSettings bad;
  bad.step_amplitude = 0.7;
  EXPECT_THROW(RegionCost(extractor, bad, 10, 0.2), std::invalid_argument);
}

}  // namespace
}  // namespace kct
