// Feature relocalizer (tracking by detection, ours): ORB keyframes of a rendered textured box
// find it again at a distant pose, anywhere in the frame, with no motion prior; an untextured
// box and an empty frame are never "found".
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "klt_contour_tracker/core/feature_relocalizer.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

class FeatureRelocalizerTest : public ::testing::Test {
 protected:
  std::shared_ptr<const Mesh> mesh_ = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Renderer renderer_{mesh_};
  PinholeCamera camera_ = test::make_camera();
  cv::Mat background_ = test::make_background(camera_.size(), 11);

  cv::Mat gray_at(const Renderer& renderer, const Pose& pose, int seed) {
    cv::Mat gray;
    cv::cvtColor(test::render_frame(renderer, camera_, pose, background_, 2.0, seed), gray,
                 cv::COLOR_BGR2GRAY);
    return gray;
  }
};

TEST_F(FeatureRelocalizerTest, FindsTheObjectFarFromItsKeyframePose) {
  const Pose keyframe_pose = test::make_pose(0.4);
  FeatureRelocalizer relocalizer(mesh_);
  ASSERT_GE(relocalizer.add_keyframe(gray_at(renderer_, keyframe_pose, 1), keyframe_pose, camera_), 50);
  // Moved by 12 cm sideways (about 180 px), 8 cm closer and turned 12 deg: far outside any
  // frame-to-frame tracker's basin.
  const Pose moved = test::move(keyframe_pose, 12.0, {0.2, 1.0, 0.4}, {0.12, -0.03, -0.08});
  const Relocalization found = relocalizer.locate(gray_at(renderer_, moved, 2), camera_);
  ASSERT_TRUE(found.found) << found.matches << " matches, " << found.inliers << " inliers";
  EXPECT_GE(found.inliers, 30);
  // Tolerances: 3 mm and 1 deg at 0.32 m for a 12 cm box with 2-level sensor noise.
  EXPECT_LT(translation_error(found.object_to_camera, moved), 0.003);
  EXPECT_LT(rotation_error_deg(found.object_to_camera, moved), 1.0);
  EXPECT_LT(found.mean_reprojection_px, 2.0);
  // The same result inside the region around the pose.
  const Relocalization in_region =
      relocalizer.locate(gray_at(renderer_, moved, 2), camera_, relocalizer.region_around(moved, camera_, 0.5));
  ASSERT_TRUE(in_region.found);
  EXPECT_LT(translation_error(in_region.object_to_camera, moved), 0.003);
}

TEST_F(FeatureRelocalizerTest, FindsASmallObjectInAFrameFullOfCorners) {
  // The box 0.75 m away (about 100 px across) over a background of 4 px colour cells: ORB's
  // strongest corners in the frame are the background's, and few of the ratio-test matches are
  // right, as on a cluttered table. Learned near the camera, found far and turned.
  const cv::Mat clutter = test::make_background(camera_.size(), 5, 8, 0, 255);
  const auto frame_at = [&](const Pose& pose, int seed) {
    cv::Mat gray;
    cv::cvtColor(test::render_frame(renderer_, camera_, pose, clutter, 2.0, seed), gray,
                 cv::COLOR_BGR2GRAY);
    return gray;
  };
  const Pose keyframe_pose = test::make_pose(0.45);
  FeatureRelocalizer relocalizer(mesh_);
  ASSERT_GE(relocalizer.add_keyframe(frame_at(keyframe_pose, 1), keyframe_pose, camera_), 50);
  const Pose far = test::move(keyframe_pose, 10.0, {0.3, 1.0, 0.2}, {0.1, 0.05, 0.15});
  const Relocalization found = relocalizer.locate(frame_at(far, 2), camera_);
  ASSERT_TRUE(found.found) << found.matches << " matches, " << found.inliers << " inliers";
  // Tolerances: 1 % of the distance and 2 deg for a 100 px box with 2-level noise.
  EXPECT_LT(translation_error(found.object_to_camera, far), 0.0075);
  EXPECT_LT(rotation_error_deg(found.object_to_camera, far), 2.0);
  // The same frame without the box: nothing, however many corners it has.
  Pose behind = far;
  behind.translation().z() = -1.0;
  EXPECT_FALSE(relocalizer.locate(frame_at(behind, 3), camera_).found);
}

TEST_F(FeatureRelocalizerTest, RegionAroundGrowsByPixelsAndIsEmptyOutsideTheImage) {
  const Pose pose = test::make_pose(0.4);
  FeatureRelocalizer relocalizer(mesh_);
  const cv::Rect tight = relocalizer.region_around(pose, camera_, 0.0);
  ASSERT_GT(tight.area(), 0);
  // 20 px on every side (exactly, up to the rounding of the corners: 1 px).
  const cv::Rect grown = relocalizer.region_around(pose, camera_, 0.0, 20.0);
  EXPECT_NEAR(grown.x, tight.x - 20, 1);
  EXPECT_NEAR(grown.y, tight.y - 20, 1);
  EXPECT_NEAR(grown.width, tight.width + 40, 2);
  EXPECT_NEAR(grown.height, tight.height + 40, 2);
  // The object 1 m to the side (far outside the image): empty, also grown by less than that.
  Pose aside = pose;
  aside.translation().x() += 1.0;
  EXPECT_EQ(relocalizer.region_around(aside, camera_, 0.0, 50.0).area(), 0);
  // A region that leaves the object out finds nothing; the same one grown to reach it does.
  ASSERT_GE(relocalizer.add_keyframe(gray_at(renderer_, pose, 1), pose, camera_), 50);
  const Pose moved = test::move(pose, 5.0, {0.2, 1.0, 0.4}, {0.12, 0.0, 0.0});  // ~180 px right
  const cv::Mat frame = gray_at(renderer_, moved, 2);
  EXPECT_FALSE(relocalizer.locate(frame, camera_, relocalizer.region_around(pose, camera_, 0.0)).found);
  const Relocalization reached =
      relocalizer.locate(frame, camera_, relocalizer.region_around(pose, camera_, 0.0, 250.0));
  ASSERT_TRUE(reached.found);
  EXPECT_LT(translation_error(reached.object_to_camera, moved), 0.003);
}

TEST_F(FeatureRelocalizerTest, NothingIsFoundWithoutTheObjectOrWithoutTexture) {
  const Pose pose = test::make_pose(0.4);
  FeatureRelocalizer relocalizer(mesh_);
  EXPECT_FALSE(relocalizer.locate(gray_at(renderer_, pose, 1), camera_).found) << "no keyframe yet";
  ASSERT_GT(relocalizer.add_keyframe(gray_at(renderer_, pose, 1), pose, camera_), 0);
  // The background alone (the object rendered behind the camera: not in the frame).
  Pose behind = pose;
  behind.translation().z() = -1.0;
  EXPECT_FALSE(relocalizer.locate(gray_at(renderer_, behind, 3), camera_).found);

  // An untextured box has no features to anchor: no keyframe is stored, nothing is found.
  const auto plain = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06, /*textured=*/false));
  const Renderer plain_renderer(plain);
  FeatureRelocalizer untextured(plain);
  untextured.add_keyframe(gray_at(plain_renderer, pose, 1), pose, camera_);
  EXPECT_EQ(untextured.keyframes(), 0);
  EXPECT_FALSE(untextured.locate(gray_at(plain_renderer, pose, 2), camera_).found);
}

TEST_F(FeatureRelocalizerTest, KeyframesAreAddedOnlyFromNewViewpoints) {
  const Pose pose = test::make_pose(0.4);
  FeatureRelocalizer relocalizer(mesh_);
  EXPECT_TRUE(relocalizer.wants_keyframe(pose));
  relocalizer.add_keyframe(gray_at(renderer_, pose, 1), pose, camera_);
  ASSERT_EQ(relocalizer.keyframes(), 1);
  EXPECT_FALSE(relocalizer.wants_keyframe(test::move(pose, 5.0, {0, 1, 0}, {0.02, 0, 0})));
  EXPECT_TRUE(relocalizer.wants_keyframe(test::move(pose, 15.0, {0, 1, 0}, {0, 0, 0})));
  relocalizer.clear();
  EXPECT_EQ(relocalizer.keyframes(), 0);
}

TEST_F(FeatureRelocalizerTest, InvalidSettingsAndFramesAreRejected) {
  FeatureRelocalizerSettings bad;
  bad.min_inliers = 2;
  EXPECT_THROW(FeatureRelocalizer(mesh_, bad), std::invalid_argument);
  FeatureRelocalizer relocalizer(mesh_);
  const cv::Mat wrong_size(100, 100, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(relocalizer.add_keyframe(wrong_size, test::make_pose(0.4), camera_), std::invalid_argument);
  EXPECT_FALSE(relocalizer.locate(wrong_size, camera_).found);
}

}  // namespace
}  // namespace kct
