#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "klt_contour_tracker/core/camera.h"

TEST(PinholeCamera, ProjectionAndBackProjectionRoundTrip) {
  const kct::PinholeCamera camera(520.0, 515.0, 321.3, 238.7, 640, 480);
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.0, 0.0, 0.5), Eigen::Vector3d(0.1, -0.05, 0.4),
        Eigen::Vector3d(-0.3, 0.2, 2.0), Eigen::Vector3d(0.01, 0.02, 0.05)}) {
    const Eigen::Vector2d pixel = camera.project(p);
    const Eigen::Vector3d ray = camera.back_project(pixel);
    EXPECT_DOUBLE_EQ(ray.z(), 1.0);
    EXPECT_LT((ray * p.z() - p).norm(), 1e-12);
  }
  // The principal point is the projection of the optical axis (OpenCV pixel-centre convention).
  const Eigen::Vector2d centre = camera.project(Eigen::Vector3d(0, 0, 1));
  EXPECT_DOUBLE_EQ(centre.x(), 321.3);
  EXPECT_DOUBLE_EQ(centre.y(), 238.7);
  // One focal length sideways at unit depth moves fx pixels.
  EXPECT_NEAR(camera.project(Eigen::Vector3d(1, 0, 1)).x() - centre.x(), 520.0, 1e-12);
  EXPECT_NEAR(camera.project(Eigen::Vector3d(0, 1, 1)).y() - centre.y(), 515.0, 1e-12);
}

TEST(PinholeCamera, MatrixRoundTripAndAccessors) {
  const cv::Matx33d K(600, 0, 300, 0, 610, 200, 0, 0, 1);
  const kct::PinholeCamera camera = kct::PinholeCamera::from_matrix(K, 800, 600);
  EXPECT_EQ(camera.K(), K);
  EXPECT_EQ(camera.size(), cv::Size(800, 600));
  EXPECT_FALSE(camera.has_distortion());
  EXPECT_FALSE(kct::PinholeCamera::from_matrix(K, 800, 600, {0, 0, 0, 0, 0}).has_distortion());
  EXPECT_TRUE(kct::PinholeCamera::from_matrix(K, 800, 600, {0.1, 0, 0, 0, 0}).has_distortion());
  EXPECT_TRUE(camera.in_image(Eigen::Vector2d(0, 0)));
  EXPECT_TRUE(camera.in_image(Eigen::Vector2d(799.9, 599.9)));
  EXPECT_FALSE(camera.in_image(Eigen::Vector2d(800, 10)));
  EXPECT_FALSE(camera.in_image(Eigen::Vector2d(-0.1, 10)));
  EXPECT_FALSE(camera.in_image(Eigen::Vector2d(5, 5), 10.0));
}

TEST(PinholeCamera, InvalidIntrinsicsThrow) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(kct::PinholeCamera(0, 500, 320, 240, 640, 480), std::invalid_argument);
  EXPECT_THROW(kct::PinholeCamera(500, -1, 320, 240, 640, 480), std::invalid_argument);
  EXPECT_THROW(kct::PinholeCamera(nan, 500, 320, 240, 640, 480), std::invalid_argument);
  EXPECT_THROW(kct::PinholeCamera(inf, 500, 320, 240, 640, 480), std::invalid_argument);
  EXPECT_THROW(kct::PinholeCamera(500, 500, nan, 240, 640, 480), std::invalid_argument);
  EXPECT_THROW(kct::PinholeCamera(500, 500, 320, 240, 0, 480), std::invalid_argument);
  EXPECT_THROW(kct::PinholeCamera(500, 500, 320, 240, 640, -5), std::invalid_argument);
  EXPECT_THROW(kct::PinholeCamera(500, 500, 320, 240, 640, 480, {0.1, nan}),
               std::invalid_argument);
  EXPECT_NO_THROW(kct::PinholeCamera(500, 500, 320, 240, 640, 480));
}
