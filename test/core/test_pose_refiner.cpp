// Contour-energy refinement (paper Sec. 3.3-3.4) on rendered frames with known poses: a
// perturbed pose is brought back, and the keypoint search area's bound is kept.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "klt_contour_tracker/core/pose_refiner.h"
#include "klt_contour_tracker/core/search_area.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

class PoseRefinerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    params_.icosphere_subdivisions = 3;  // 642 views: enough for a box, faster to build
    refiner_ = std::make_unique<PoseRefiner>(mesh_, params_);
    cv::cvtColor(test::render_frame(renderer_, camera_, truth_, background_, 2.0, 1), gray_,
                 cv::COLOR_BGR2GRAY);
  }

  std::shared_ptr<const Mesh> mesh_ = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Renderer renderer_{mesh_};
  PinholeCamera camera_ = test::make_camera();
  // An object on a dark, mildly textured table: the silhouette is the strongest edge.
  cv::Mat background_ = test::make_background(camera_.size(), 21, 32, 10, 60);
  Pose truth_ = test::make_pose(0.45);
  TrackerParams params_ = make_preset("paper");
  std::unique_ptr<PoseRefiner> refiner_;
  cv::Mat gray_;
};

TEST_F(PoseRefinerTest, EnergyIsHigherAtTheTruePose) {
  const Pose off = test::move(truth_, 4.0, {1, 0, 0}, {0.004, 0, 0});
  EXPECT_GT(refiner_->energy(gray_, camera_, truth_), refiner_->energy(gray_, camera_, off));
}

TEST_F(PoseRefinerTest, BringsBackAnExtrapolatedPosePerturbedBySevenDegreesAndFivePercent) {
  // 7 deg about a generic axis and 5% of the 0.156 m size, well inside the +-30 deg /
  // +-0.1 size box of Sec. 3.4.
  const double size = mesh_->diameter();
  const Pose perturbed = test::move(truth_, 7.0, {0.5, -1.0, 0.3},
                                    Eigen::Vector3d(0.6, -0.5, 0.6).normalized() * 0.05 * size);
  ASSERT_GT(rotation_error_deg(perturbed, truth_), 6.0);
  const RefineResult result = refiner_->refine(gray_, camera_, perturbed, nullptr);
  // Tolerance: 2 mm and 1 deg (the edges of a 0.45 m distant box, 2-level noise).
  EXPECT_LT(translation_error(result.object_to_camera, truth_), 0.002);
  EXPECT_LT(rotation_error_deg(result.object_to_camera, truth_), 1.0);
  EXPECT_GT(result.energy_after, result.energy_before);
  EXPECT_GT(result.hops, params_.final_hops);
}

TEST_F(PoseRefinerTest, KeypointSearchAreaKeepsTheReprojectionBound) {
  // Keypoints whose PnP pose is off by 3 deg: the refined pose may move only as far as the
  // average reprojection error grows by at most E_max = 2.5 px.
  const Pose pnp = test::move(truth_, 3.0, {0, 1, 0}, {0.003, 0, 0});
  KeypointResult keypoints;
  keypoints.success = true;
  keypoints.object_to_camera = pnp;
  for (const Eigen::Vector3d& v : mesh_->vertices) {
    keypoints.inlier_points.points_object.push_back(v);
    keypoints.inlier_points.points_image.push_back(camera_.project(pnp * v));
  }
  const RefineResult result = refiner_->refine(gray_, camera_, pnp, &keypoints);
  const ReprojectionConstraint constraint(keypoints.inlier_points.points_object,
                                          keypoints.inlier_points.points_image, camera_, pnp,
                                          params_.max_reprojection_increase_px);
  EXPECT_LE(constraint.average_error_px(result.object_to_camera), 2.5 + 1e-3);
  // ... and it moves towards the truth, which is outside the bound.
  EXPECT_LT(rotation_error_deg(result.object_to_camera, truth_), rotation_error_deg(pnp, truth_));
}

TEST_F(PoseRefinerTest, ShiftSearchFindsAnObjectThatMovedFarWhenKltFailed) {
  // The object moved 0.35 diameters sideways (a fast hand-held move that defeats KLT): the
  // coarse-to-fine optimizer's basin (a few coarsest-level px) does not reach it from the
  // last pose; the shift search over 0.8 diameters does.
  const double size = mesh_->diameter();
  const Pose stale = test::move(truth_, 0.0, {0, 0, 1}, {0.35 * size * 0.8, 0.35 * size * 0.6, 0});
  TrackerParams params = make_preset("realtime");
  params.icosphere_subdivisions = 3;
  params.shift_search_diameters = 0.0;
  PoseRefiner without(mesh_, params);
  const RefineResult stuck = without.refine(gray_, camera_, stale, nullptr);
  // Tolerance: the test is meaningful only if the search is needed (the pose stays > 2 cm off).
  EXPECT_GT(translation_error(stuck.object_to_camera, truth_), 0.02);
  params.shift_search_diameters = 0.8;
  // Every shift scored, and every second one then the neighbours of the best (the preset's).
  for (const bool coarse_to_fine : {false, true}) {
    SCOPED_TRACE(coarse_to_fine ? "coarse to fine" : "every shift");
    params.shift_search_coarse_to_fine = coarse_to_fine;
    PoseRefiner with(mesh_, params);
    // Also a move the other way, to an odd cell of the search grid.
    for (const Pose& start :
         {stale, test::move(truth_, 0.0, {0, 0, 1}, {-0.3 * size * 0.6, 0.3 * size * 0.8, 0})}) {
      const RefineResult found = with.refine(gray_, camera_, start, nullptr);
      // Tolerance: 3 mm and 2 deg (coarse-to-fine accuracy on a 0.45 m distant box).
      EXPECT_LT(translation_error(found.object_to_camera, truth_), 0.003);
      EXPECT_LT(rotation_error_deg(found.object_to_camera, truth_), 2.0);
    }
  }
}

TEST_F(PoseRefinerTest, ShiftSearchKeepsAPoseThatIsAlreadyRight) {
  // At the true pose no shift beats staying put 1.5 x: the pose is not lured to other edges.
  TrackerParams params = make_preset("realtime");
  params.icosphere_subdivisions = 3;
  PoseRefiner refiner(mesh_, params);
  ASSERT_GT(params.shift_search_diameters, 0.0);
  const RefineResult result = refiner.refine(gray_, camera_, truth_, nullptr);
  EXPECT_LT(translation_error(result.object_to_camera, truth_), 0.002);
}

/// pyramid_min_object_px: the refinement starts at the coarsest level where the object's
/// diameter is still at least that many px (level l: 1 / 2^l of the resolution).
TEST_F(PoseRefinerTest, ASmallObjectIsRefinedFromAFinerPyramidLevel) {
  TrackerParams params = make_preset("realtime");
  params.icosphere_subdivisions = 3;
  ASSERT_EQ(params.pyramid_levels, 3);
  params.pyramid_min_object_px = 40.0;
  PoseRefiner refiner(mesh_, params);
  // The distance at which the box's diameter is `px` across.
  const auto at_size = [&](double px) {
    return test::make_pose(camera_.fx() * mesh_->diameter() / px);
  };
  EXPECT_EQ(refiner.coarsest_level(camera_, at_size(200.0)), 2);  // 50 px at level 2
  EXPECT_EQ(refiner.coarsest_level(camera_, at_size(150.0)), 1);  // 37.5 at level 2, 75 at 1
  EXPECT_EQ(refiner.coarsest_level(camera_, at_size(79.0)), 0);   // 39.5 at level 1
  EXPECT_EQ(refiner.coarsest_level(camera_, at_size(20.0)), 0);
  params.pyramid_min_object_px = 0.0;  // off: always the pyramid's coarsest
  PoseRefiner off(mesh_, params);
  EXPECT_EQ(off.coarsest_level(camera_, at_size(20.0)), 2);
}

TEST_F(PoseRefinerTest, ASmallObjectRefinedFromAFinerLevelComesBack) {
  // The box 1.3 m away (about 70 px across) on the textured table, the extrapolated pose
  // 4 % too far and 3 deg turned.
  const Pose far = test::make_pose(1.3);
  cv::Mat gray;
  cv::cvtColor(test::render_frame(renderer_, camera_, far, background_, 2.0, 1), gray,
               cv::COLOR_BGR2GRAY);
  const Pose off = test::move(far, 3.0, {0, 1, 0}, far.translation() * 0.04);
  TrackerParams params = make_preset("realtime");
  params.icosphere_subdivisions = 3;
  params.pyramid_min_object_px = 40.0;
  PoseRefiner refiner(mesh_, params);
  ASSERT_EQ(refiner.coarsest_level(camera_, off), 0);
  const RefineResult result = refiner.refine(gray, camera_, off, nullptr);
  // Tolerance: 1.5 % of the distance and 2 deg (a pixel of a 70 px silhouette is 1.4 %).
  EXPECT_LT(translation_error(result.object_to_camera, far), 0.015 * 1.3);
  EXPECT_LT(rotation_error_deg(result.object_to_camera, far), 2.0);
  // From the pyramid's coarsest level (the box 18 px across there) the refinement turns it away:
  // the finer start is what brings it back.
  params.pyramid_min_object_px = 0.0;
  PoseRefiner coarse(mesh_, params);
  EXPECT_GT(rotation_error_deg(coarse.refine(gray, camera_, off, nullptr).object_to_camera, far), 5.0);
}

TEST_F(PoseRefinerTest, SameSeedSameResult) {
  const Pose perturbed = test::move(truth_, 4.0, {0, 0, 1}, {0.0, 0.004, 0.0});
  PoseRefiner a(mesh_, params_), b(mesh_, params_);
  const RefineResult ra = a.refine(gray_, camera_, perturbed, nullptr);
  const RefineResult rb = b.refine(gray_, camera_, perturbed, nullptr);
  EXPECT_EQ((ra.object_to_camera.matrix() - rb.object_to_camera.matrix()).norm(), 0.0);
}

}  // namespace
}  // namespace kct
