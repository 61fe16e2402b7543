// The `realtime` refinement (coarse-to-fine Levenberg-Marquardt on the weighted cues) on rendered
// frames with known poses: a perturbed pose is brought back with and without keypoints, the
// keypoint cue keeps the pose on good keypoints, a step along a nearly flat direction is bounded,
// and nothing depends on the thread count.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "klt_contour_tracker/core/coarse_to_fine_optimizer.h"
#include "klt_contour_tracker/core/motion_model.h"
#include "klt_contour_tracker/core/pose_refiner.h"
#include "klt_contour_tracker/core/tracker.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

class CoarseToFineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    params_.icosphere_subdivisions = 3;  // 642 views: enough for a box, faster to build
    cv::cvtColor(test::render_frame(renderer_, camera_, truth_, background_, 2.0, 1), gray_,
                 cv::COLOR_BGR2GRAY);
  }
  /// KLT-like inliers: the box's corners seen at `pose`, plus `noise_px` of seeded noise.
  KeypointResult keypoints_at(const Pose& pose, double noise_px) const {
    KeypointResult keypoints;
    keypoints.success = true;
    keypoints.object_to_camera = pose;
    cv::RNG rng(4);
    for (const Eigen::Vector3d& v : mesh_->vertices) {
      keypoints.inlier_points.points_object.push_back(v);
      keypoints.inlier_points.points_image.push_back(
          camera_.project(pose * v) +
          Eigen::Vector2d(rng.gaussian(noise_px), rng.gaussian(noise_px)));
    }
    keypoints.inliers = keypoints.tracked = static_cast<int>(mesh_->vertices.size());
    keypoints.inlier_ratio = 1.0;
    return keypoints;
  }

  std::shared_ptr<const Mesh> mesh_ = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Renderer renderer_{mesh_};
  PinholeCamera camera_ = test::make_camera();
  // An object on a dark, mildly textured table: the silhouette is the strongest edge.
  cv::Mat background_ = test::make_background(camera_.size(), 21, 32, 10, 60);
  Pose truth_ = test::make_pose(0.45);
  TrackerParams params_ = make_preset("realtime");
  cv::Mat gray_;
};

TEST_F(CoarseToFineTest, BringsBackAnExtrapolatedPosePerturbedByTwoDegreesAndTwoPercent) {
  // A local method: the pyramid widens its basin to a few pixels (here ~5 px of contour
  // motion), not to the paper preset's +-30 deg box.
  PoseRefiner refiner(mesh_, params_);
  const double size = mesh_->diameter();
  const Pose perturbed = test::move(truth_, 2.0, {0.5, -1.0, 0.3},
                                    Eigen::Vector3d(0.6, -0.5, 0.6).normalized() * 0.02 * size);
  ASSERT_GT(rotation_error_deg(perturbed, truth_), 1.5);
  const RefineResult result = refiner.refine(gray_, camera_, perturbed, nullptr);
  // Tolerance: 2 mm and 1 deg, as the paper preset's test (a 0.45 m distant box, 2-level noise).
  EXPECT_TRUE(result.accepted);
  EXPECT_LT(translation_error(result.object_to_camera, truth_), 0.002);
  EXPECT_LT(rotation_error_deg(result.object_to_camera, truth_), 1.0);
  EXPECT_GT(result.energy_after, result.energy_before);
}

TEST_F(CoarseToFineTest, ContourAndKeypointsTogetherBeatNoisyKeypoints) {
  // PnP from noisy keypoints is off by 2 deg and 3 mm; the contour pulls it back while the
  // keypoint cue (consistent with the truth up to 1 px noise) keeps it there.
  PoseRefiner refiner(mesh_, params_);
  const KeypointResult keypoints = keypoints_at(truth_, 1.0);
  const Pose pnp = test::move(truth_, 2.0, {0.2, 1.0, 0.0}, {0.003, 0.0, 0.0});
  const RefineResult result = refiner.refine(gray_, camera_, pnp, &keypoints);
  // Tolerance: 1 mm and 0.5 deg.
  EXPECT_LT(translation_error(result.object_to_camera, truth_), 0.001);
  EXPECT_LT(rotation_error_deg(result.object_to_camera, truth_), 0.5);
}

TEST_F(CoarseToFineTest, KeypointCueHoldsThePoseWhenTheContourIsMisleading) {
  // The frame shows the box 3 deg away from where good keypoints put it (as if the contour
  // locked onto clutter): with a strong keypoint weight the result stays within 1 deg of the
  // keypoints' pose; with the keypoint cue off it follows the image.
  const Pose keypoint_pose = test::move(truth_, 3.0, {0.0, 1.0, 0.0}, {0.0, 0.0, 0.0});
  const KeypointResult keypoints = keypoints_at(keypoint_pose, 0.0);
  TrackerParams strong = params_;
  strong.keypoint_weight = 10.0;
  PoseRefiner held(mesh_, strong);
  EXPECT_LT(rotation_error_deg(held.refine(gray_, camera_, keypoint_pose, &keypoints)
                                   .object_to_camera,
                               keypoint_pose),
            1.0);
  TrackerParams contour_only = params_;
  contour_only.keypoint_weight = 0.0;
  PoseRefiner free(mesh_, contour_only);
  EXPECT_LT(rotation_error_deg(free.refine(gray_, camera_, keypoint_pose, &keypoints)
                                   .object_to_camera,
                               truth_),
            1.0);
}

TEST_F(CoarseToFineTest, NoTermsNoMove) {
  PoseCostSum empty;
  PoseCostFrame frame;
  frame.levels = make_pyramid(gray_, camera_, 2);
  const CoarseToFineResult result =
      CoarseToFineOptimizer().minimize(empty, frame, truth_, 0.1, CoarseToFineSettings());
  EXPECT_TRUE(result.object_to_camera.isApprox(truth_, 0.0));
  EXPECT_THROW(CoarseToFineOptimizer().minimize(empty, PoseCostFrame(), truth_, 0.1,
                                                CoarseToFineSettings()),
               std::invalid_argument);
}

/// A cue with a nearly flat, sloped direction: a rotation about `axis` (not a coordinate axis),
/// curvature `flat_curvature`, slope `slope`; every other direction has curvature 1. Its
/// minimum lies at a rotation of slope / flat_curvature rad about -axis.
class FlatDirectionCost : public PoseCost {
 public:
  FlatDirectionCost(const Pose& start, const Eigen::Vector3d& axis, double slope,
                    double flat_curvature)
      : start_(start), axis_(axis.normalized()), slope_(slope), flat_(flat_curvature) {}
  std::string name() const override { return "flat"; }
  void begin_frame(const PoseCostFrame& frame) override { center_ = frame.center_object; }
  void linearize(const Pose&, int) override {}
  double evaluate(const Pose& pose, Vector6d* gradient, Matrix6d* hessian) const override {
    const Vector6d e = motion_increment_between(start_, pose, center_);
    Vector6d u = Vector6d::Zero();
    u.head<3>() = axis_;
    const double along = u.dot(e);
    const Vector6d across = e - along * u;
    if (gradient) *gradient += (slope_ + flat_ * along) * u + across;
    if (hessian) *hessian += flat_ * u * u.transpose() + (Matrix6d::Identity() - u * u.transpose());
    return slope_ * along + 0.5 * flat_ * along * along + 0.5 * across.squaredNorm();
  }

 private:
  Pose start_;
  Eigen::Vector3d axis_;
  double slope_, flat_;
  Eigen::Vector3d center_ = Eigen::Vector3d::Zero();
};

TEST(CoarseToFineStep, MaxStepBoundsAStepAlongANearlyFlatDirection) {
  // One full-resolution linearization: unbounded, the step heads for the cue's minimum 1.5 rad
  // (86 deg) away (Marquardt's damping of the off-axis diagonal shortens it to ~49 deg), as the
  // can's blurred outline let it turn 145 deg; with max_step_px = 8 the model points move by
  // at most 8 px, along the same axis.
  const PinholeCamera camera = test::make_camera();
  const Pose start = test::make_pose(0.45);
  PoseCostFrame frame;
  frame.levels = make_pyramid(cv::Mat(camera.size(), CV_8UC1, cv::Scalar(0)), camera, 1);
  frame.center_object = Eigen::Vector3d::Zero();
  const Eigen::Vector3d axis(1.0, 1.0, 0.0);
  PoseCostSum cost;
  cost.add(std::make_shared<FlatDirectionCost>(start, axis, 1e-3, 1e-3 / 1.5), 1.0);
  const double radius_m = 0.07;
  CoarseToFineSettings settings;
  settings.iterations_per_level = 1;
  const CoarseToFineOptimizer optimizer;
  const Pose unbounded =
      optimizer.minimize(cost, frame, start, radius_m, settings).object_to_camera;
  EXPECT_GT(rotation_error_deg(unbounded, start), 30.0);
  settings.max_step_px = 8.0;
  const Pose bounded = optimizer.minimize(cost, frame, start, radius_m, settings).object_to_camera;
  const double px_per_rad = camera.fx() * radius_m / (start * frame.center_object).z();
  const double bound_deg = 8.0 / px_per_rad * 180.0 / M_PI;  // 5.5 deg
  // Tolerance: 1e-6 deg of round-off; the step still lowers the cost, so it is taken.
  EXPECT_LE(rotation_error_deg(bounded, start), bound_deg + 1e-6);
  EXPECT_GT(rotation_error_deg(bounded, start), 0.99 * bound_deg);
  const Vector6d e = motion_increment_between(start, bounded, frame.center_object);
  EXPECT_GT(-e.head<3>().normalized().dot(axis.normalized()), 0.999);  // the same direction
  EXPECT_LT(e.tail<3>().norm(), 1e-9);
}

TEST(CoarseToFineTracker, ResultDoesNotDependOnTheThreadCount) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Renderer renderer(mesh);
  const PinholeCamera camera = test::make_camera();
  const cv::Mat background = test::make_background(camera.size(), 5);
  TrackerParams one = make_preset("realtime");
  one.icosphere_subdivisions = 2;
  one.num_threads = 1;
  TrackerParams two = one;
  two.num_threads = 2;
  Tracker a(mesh, camera, one), b(mesh, camera, two);
  Pose truth = test::make_pose(0.45);
  a.initialize(truth);
  b.initialize(truth);
  for (int i = 0; i < 8; ++i) {
    if (i > 0) truth = test::move(truth, 1.5, {0.2, 1.0, 0.1}, {0.004, 0.001, -0.002});
    const cv::Mat image = test::render_frame(renderer, camera, truth, background, 2.0, i);
    const TrackResult ra = a.track({image, i / 30.0}), rb = b.track({image, i / 30.0});
    ASSERT_EQ(ra.status, rb.status);
    EXPECT_EQ((ra.object_to_camera.matrix() - rb.object_to_camera.matrix()).norm(), 0.0)
        << "frame " << i;
    // And it tracks: within 3 mm and 1.5 deg of the truth.
    EXPECT_LT(translation_error(ra.object_to_camera, truth), 0.003) << "frame " << i;
    EXPECT_LT(rotation_error_deg(ra.object_to_camera, truth), 1.5) << "frame " << i;
  }
}

}  // namespace
}  // namespace kct
