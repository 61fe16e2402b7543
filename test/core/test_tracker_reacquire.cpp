// Tracker::reacquire(): contour refinement from a given pose in a widened search box, then
// keypoint tracking resumes from the result. A coarse visibility table keeps the test quick.
#include <gtest/gtest.h>

#include "klt_contour_tracker/core/tracker.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

TrackerParams quick_paper() {
  TrackerParams params = make_preset("paper");
  params.icosphere_subdivisions = 2;
  params.visibility_resolution_px = 128;
  return params;
}

TEST(TrackerReacquire, RecoversAnOffsetPoseAndKeypointTrackingResumes) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Renderer renderer(mesh);
  const PinholeCamera camera = test::make_camera();
  const cv::Mat background = test::make_background(camera.size(), 5);
  const Pose truth = test::make_pose(0.45);
  // The last good pose is 8 mm and 4 deg away from the object's pose now.
  const Pose around = test::move(truth, 4.0, {0.3, 1.0, 0.0}, {0.008, -0.004, 0.0});
  ASSERT_GT(translation_error(around, truth), 0.008);
  Tracker tracker(mesh, camera, quick_paper());
  const cv::Mat frame = test::render_frame(renderer, camera, truth, background, 1.0, 1);
  const TrackResult result = tracker.reacquire({frame, 0.1}, around, 2.0);
  ASSERT_EQ(result.status, TrackStatus::kReacquired);
  EXPECT_TRUE(result.refined);
  EXPECT_GT(result.energy_after, result.energy_before);
  // Tolerance: 3 mm and 1.5 deg from 8 mm / 4 deg (a coarse visibility table, 12 cm box).
  EXPECT_LT(translation_error(result.object_to_camera, truth), 0.003);
  EXPECT_LT(rotation_error_deg(result.object_to_camera, truth), 1.5);
  EXPECT_TRUE(tracker.is_initialized());

  // Keypoints were re-anchored on the re-acquired pose: the next frame is tracked by KLT.
  const Pose next = test::move(truth, 1.0, {0, 1, 0}, {0.002, 0.0, 0.0});
  const TrackResult tracked =
      tracker.track({test::render_frame(renderer, camera, next, background, 1.0, 2), 0.2});
  EXPECT_EQ(tracked.status, TrackStatus::kKeypoints);
  EXPECT_LT(translation_error(tracked.object_to_camera, next), 0.004);
  EXPECT_LT(rotation_error_deg(tracked.object_to_camera, next), 2.0);
}

TEST(TrackerReacquire, HypothesesOnTwoThreadsGiveTheOneThreadResults) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Renderer renderer(mesh);
  const PinholeCamera camera = test::make_camera();
  const Pose truth = test::make_pose(0.45);
  const cv::Mat frame = test::render_frame(renderer, camera, truth,
                                           test::make_background(camera.size(), 5), 1.0, 1);
  // Five hypotheses around the truth (an odd count: the threads get 3 and 2).
  std::vector<Pose> around;
  for (int k = 0; k < 5; ++k)
    around.push_back(test::move(truth, 2.0 * k, {0.3, 1.0, 0.2}, {0.004 * k, -0.002 * k, 0.0}));
  TrackerParams params = make_preset("realtime");
  params.icosphere_subdivisions = 2;
  params.visibility_resolution_px = 128;
  params.num_threads = 1;
  Tracker serial(mesh, camera, params);
  params.num_threads = 2;
  Tracker parallel(mesh, camera, params);
  for (const bool shift_search : {true, false}) {
    const std::vector<TrackResult> one = serial.refine_hypotheses({frame, 0.1}, around, 1.0, shift_search);
    const std::vector<TrackResult> two = parallel.refine_hypotheses({frame, 0.1}, around, 1.0, shift_search);
    ASSERT_EQ(one.size(), around.size());
    ASSERT_EQ(two.size(), around.size());
    for (std::size_t i = 0; i < around.size(); ++i) {
      SCOPED_TRACE(i);
      EXPECT_TRUE(one[i].refined);
      EXPECT_EQ(two[i].status, TrackStatus::kReacquired);
      // Bit for bit: each refinement depends only on its hypothesis and the frame.
      EXPECT_EQ((one[i].object_to_camera.matrix() - two[i].object_to_camera.matrix()).cwiseAbs().maxCoeff(),
                0.0);
      EXPECT_EQ(one[i].energy_after, two[i].energy_after);
    }
    // The refinement did its work: the hypotheses closest to the truth end within 3 mm.
    EXPECT_LT(translation_error(two[1].object_to_camera, truth), 0.003);
  }
}

TEST(TrackerReacquire, WithoutRefinementTheGivenPoseIsTaken) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Tracker tracker(mesh, test::make_camera(), make_preset("klt_only"));
  const cv::Mat image(480, 640, CV_8UC3, cv::Scalar(90, 90, 90));
  const Pose around = test::make_pose(0.4);
  const TrackResult result = tracker.reacquire({image, 0.0}, around, 3.0);
  EXPECT_EQ(result.status, TrackStatus::kReacquired);
  EXPECT_FALSE(result.refined);
  EXPECT_LT(translation_error(result.object_to_camera, around), 1e-12);
  EXPECT_LT(translation_error(tracker.last_pose(), around), 1e-12);
}

TEST(TrackerReacquire, RejectsBadInputAndArguments) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Tracker tracker(mesh, test::make_camera(), make_preset("klt_only"));
  const Pose around = test::make_pose(0.4);
  EXPECT_EQ(tracker.reacquire({cv::Mat(), 0.0}, around, 2.0).status, TrackStatus::kInvalidInput);
  EXPECT_EQ(tracker.reacquire({cv::Mat(240, 320, CV_8UC1), 0.0}, around, 2.0).status,
            TrackStatus::kInvalidInput);
  EXPECT_FALSE(tracker.is_initialized());
  const cv::Mat image(480, 640, CV_8UC1, cv::Scalar(90));
  EXPECT_THROW(tracker.reacquire({image, 0.0}, around, 0.5), std::invalid_argument);
  Pose behind = around;
  behind.translation().z() = -0.4;
  EXPECT_THROW(tracker.reacquire({image, 0.0}, behind, 2.0), std::invalid_argument);
  EXPECT_STREQ(to_string(TrackStatus::kReacquired), "reacquired");
}

}  // namespace
}  // namespace kct
