// The debug overlay draws the contour where the object is, keypoints, and nothing without a pose.
#include <gtest/gtest.h>

#include "klt_contour_tracker/core/debug_drawing.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

TEST(DebugDrawing, DrawsTheContourOnTheObjectsSilhouette) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06, /*textured=*/false));
  const PinholeCamera camera = test::make_camera();
  const Pose pose = test::make_pose(0.45);
  const cv::Mat black(camera.size(), CV_8UC1, cv::Scalar(0));
  const ContourExtractor extractor(mesh, nullptr, 45.0);
  TrackResult result;
  result.status = TrackStatus::kKeypoints;
  result.object_to_camera = pose;
  result.keypoints.inlier_points.points_image.push_back({100.0, 400.0});
  const cv::Mat overlay = draw_tracking_overlay(black, result, camera, *mesh, mesh->diameter(), &extractor, "TRACKING");
  ASSERT_EQ(overlay.type(), CV_8UC3);
  // Green contour pixels lie on the boundary of the rendered silhouette (within 2 px).
  const cv::Mat mask = Renderer(mesh).render(pose, camera).mask();
  cv::Mat boundary;
  cv::morphologyEx(mask, boundary, cv::MORPH_GRADIENT, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}));
  int green = 0, green_on_boundary = 0;
  for (int y = 30; y < overlay.rows; ++y)
    for (int x = 0; x < overlay.cols; ++x) {
      const cv::Vec3b c = overlay.at<cv::Vec3b>(y, x);
      if (c[1] > 150 && c[0] < 80 && c[2] < 80) {
        ++green;
        if (boundary.at<uchar>(y, x)) ++green_on_boundary;
      }
    }
  EXPECT_GT(green, 200);
  // Most green is contour; the rest is the object frame's y axis (green, RViz convention).
  EXPECT_GT(green_on_boundary, 0.75 * green);
  // The keypoint marker is drawn in cyan.
  const cv::Vec3b marker = overlay.at<cv::Vec3b>(400, 100);
  EXPECT_GT(marker[0], 200);
  EXPECT_GT(marker[1], 200);
}

TEST(DebugDrawing, DrawsOnlyTheStatusLineWithoutAPose) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  const PinholeCamera camera = test::make_camera();
  const cv::Mat black(camera.size(), CV_8UC3, cv::Scalar(0, 0, 0));
  TrackResult result;  // kNotInitialized
  const cv::Mat overlay = draw_tracking_overlay(black, result, camera, *mesh, mesh->diameter(), nullptr);
  EXPECT_EQ(cv::countNonZero(overlay.rowRange(30, overlay.rows).reshape(1)), 0);
  EXPECT_GT(cv::countNonZero(overlay.rowRange(0, 22).reshape(1)), 0);
}

// The axes are 0.3 x the diameter given (the caller's cached value, not recomputed per frame):
// the red x axis is twice as long for twice the diameter.
TEST(DebugDrawing, AxesLengthFollowsTheGivenDiameter) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  const PinholeCamera camera = test::make_camera();
  const cv::Mat black(camera.size(), CV_8UC3, cv::Scalar(0, 0, 0));
  TrackResult result;
  result.status = TrackStatus::kKeypoints;
  result.object_to_camera = test::make_pose(0.8);
  auto red_pixels = [&](double diameter_m) {
    // No extractor and a box whose faces meet at 90 deg: its edges are drawn in yellow
    // (G 220), so "red" below is the x axis alone.
    const cv::Mat overlay = draw_tracking_overlay(black, result, camera, *mesh, diameter_m, nullptr);
    int red = 0;
    for (int y = 30; y < overlay.rows; ++y)
      for (int x = 0; x < overlay.cols; ++x) {
        const cv::Vec3b c = overlay.at<cv::Vec3b>(y, x);
        if (c[2] > 150 && c[1] < 80 && c[0] < 80) ++red;
      }
    return red;
  };
  const int short_axis = red_pixels(0.2), long_axis = red_pixels(0.4);
  EXPECT_GT(short_axis, 20);
  EXPECT_NEAR(static_cast<double>(long_axis) / short_axis, 2.0, 0.4);
}

}  // namespace
}  // namespace kct
