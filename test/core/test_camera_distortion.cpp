// PinholeCamera distortion models: the undistortion maps send every ideal pixel to where the
// lens model (OpenCV radial-tangential or fisheye) puts it in the distorted image.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <stdexcept>
#include <vector>

#include "klt_contour_tracker/core/camera.h"

namespace {

// Ideal pixels spread over the image, away from the border where fisheye maps leave the image.
std::vector<cv::Point2d> ideal_pixels(const kct::PinholeCamera& camera) {
  std::vector<cv::Point2d> pixels;
  for (double fy : {0.2, 0.5, 0.8})
    for (double fx : {0.2, 0.5, 0.8}) pixels.emplace_back(fx * camera.width(), fy * camera.height());
  return pixels;
}

std::vector<cv::Point2d> normalized(const kct::PinholeCamera& camera,
                                    const std::vector<cv::Point2d>& pixels) {
  std::vector<cv::Point2d> out;
  for (const auto& p : pixels)
    out.emplace_back((p.x - camera.cx()) / camera.fx(), (p.y - camera.cy()) / camera.fy());
  return out;
}

void expect_maps_match(const kct::PinholeCamera& camera, const std::vector<cv::Point2d>& ideal,
                       const std::vector<cv::Point2d>& distorted) {
  cv::Mat map_x, map_y;
  camera.undistortion_maps(map_x, map_y);
  ASSERT_EQ(map_x.size(), camera.size());
  ASSERT_EQ(map_x.type(), CV_32FC1);
  for (size_t i = 0; i < ideal.size(); ++i) {
    const int u = static_cast<int>(ideal[i].x), v = static_cast<int>(ideal[i].y);
    ASSERT_EQ(u, ideal[i].x);  // integer pixels: the map is sampled there
    EXPECT_NEAR(map_x.at<float>(v, u), distorted[i].x, 0.01) << "pixel " << u << "," << v;
    EXPECT_NEAR(map_y.at<float>(v, u), distorted[i].y, 0.01) << "pixel " << u << "," << v;
  }
}

TEST(CameraDistortion, RadialTangentialMapsFollowTheLensModel) {
  const std::vector<double> d = {-0.28, 0.07, 0.001, -0.0005, 0.0};
  const kct::PinholeCamera camera(500, 505, 321, 239, 640, 480, d);
  EXPECT_EQ(camera.distortion_model(), kct::DistortionModel::kRadialTangential);
  const auto ideal = ideal_pixels(camera);
  std::vector<cv::Point3d> rays;
  for (const auto& n : normalized(camera, ideal)) rays.emplace_back(n.x, n.y, 1.0);
  std::vector<cv::Point2d> distorted;
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera.K(), d, distorted);
  expect_maps_match(camera, ideal, distorted);
}

TEST(CameraDistortion, EquidistantMapsFollowTheFisheyeModel) {
  const std::vector<double> d = {-0.013, 0.02, -0.011, 0.002};
  const kct::PinholeCamera camera(380, 381, 320, 240, 640, 480, d,
                                  kct::DistortionModel::kEquidistant);
  EXPECT_TRUE(camera.has_distortion());
  const auto ideal = ideal_pixels(camera);
  std::vector<cv::Point2d> distorted;
  cv::fisheye::distortPoints(normalized(camera, ideal), distorted, camera.K(), d);
  expect_maps_match(camera, ideal, distorted);
  // The fisheye map differs from reading the same coefficients as radial-tangential.
  const kct::PinholeCamera wrong(380, 381, 320, 240, 640, 480, {d[0], d[1], 0.0, 0.0, d[2]});
  cv::Mat fx, fy, wx, wy;
  camera.undistortion_maps(fx, fy);
  wrong.undistortion_maps(wx, wy);
  EXPECT_GT(cv::norm(fx, wx, cv::NORM_INF), 1.0);
}

TEST(CameraDistortion, NoDistortionGivesNoMaps) {
  const kct::PinholeCamera camera(500, 500, 320, 240, 640, 480, {0, 0, 0, 0},
                                  kct::DistortionModel::kEquidistant);
  cv::Mat map_x(2, 2, CV_32FC1), map_y(2, 2, CV_32FC1);
  camera.undistortion_maps(map_x, map_y);
  EXPECT_TRUE(map_x.empty());
  EXPECT_TRUE(map_y.empty());
}

TEST(CameraDistortion, EquidistantNeedsFourCoefficients) {
  EXPECT_THROW(kct::PinholeCamera(500, 500, 320, 240, 640, 480, {0.1, 0.0, 0.0, 0.0, 0.0},
                                  kct::DistortionModel::kEquidistant),
               std::invalid_argument);
  EXPECT_THROW(kct::PinholeCamera::from_matrix(cv::Matx33d(500, 0, 320, 0, 500, 240, 0, 0, 1),
                                               640, 480, {0.1},
                                               kct::DistortionModel::kEquidistant),
               std::invalid_argument);
}

}  // namespace
