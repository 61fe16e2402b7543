#pragma once
/// \file camera.h
/// Pinhole camera model: intrinsics K in pixels and an image size. Lens distortion (OpenCV
/// radial-tangential coefficients, i.e. ROS plumb_bob / rational_polynomial, or OpenCV fisheye
/// coefficients, i.e. ROS equidistant) is optional; when present the tracker undistorts incoming
/// frames once and then works with the ideal pinhole model.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

namespace kct {

/// How PinholeCamera::distortion() is interpreted.
enum class DistortionModel {
  kRadialTangential,  ///< OpenCV k1 k2 p1 p2 [k3 [k4 k5 k6]] (cv::undistort; ROS plumb_bob, rational_polynomial)
  kEquidistant,       ///< OpenCV fisheye k1 k2 k3 k4 (cv::fisheye; ROS equidistant)
};

/// Pinhole camera: fx, fy, cx, cy in pixels, image size in pixels, optional distortion.
class PinholeCamera {
 public:
  PinholeCamera() = default;
  /// Throws std::invalid_argument when a focal length is not positive/finite, the size is empty,
  /// a coefficient is not finite or an equidistant model does not have exactly 4 coefficients.
  PinholeCamera(double fx, double fy, double cx, double cy, int width, int height,
                std::vector<double> distortion = {},
                DistortionModel model = DistortionModel::kRadialTangential);
  /// From a 3x3 K (row-major) and the image size.
  static PinholeCamera from_matrix(const cv::Matx33d& K, int width, int height,
                                   std::vector<double> distortion = {},
                                   DistortionModel model = DistortionModel::kRadialTangential);

  double fx() const { return fx_; }
  double fy() const { return fy_; }
  double cx() const { return cx_; }
  double cy() const { return cy_; }
  int width() const { return width_; }
  int height() const { return height_; }
  cv::Size size() const { return {width_, height_}; }
  cv::Matx33d K() const;
  /// OpenCV distortion coefficients (empty when the images are undistorted/rectified).
  const std::vector<double>& distortion() const { return distortion_; }
  DistortionModel distortion_model() const { return distortion_model_; }
  bool has_distortion() const;
  /// Maps for cv::remap from a distorted image of this camera to the ideal pinhole image with
  /// the same K and size (CV_32FC1, pixels); both released when !has_distortion().
  void undistortion_maps(cv::Mat& map_x, cv::Mat& map_y) const;

  /// Projects a camera-frame point (metres, z > 0) to pixel coordinates (ideal pinhole).
  Eigen::Vector2d project(const Eigen::Vector3d& point_camera) const {
    return {fx_ * point_camera.x() / point_camera.z() + cx_,
            fy_ * point_camera.y() / point_camera.z() + cy_};
  }
  /// Unit-depth ray (x, y, 1) through a pixel.
  Eigen::Vector3d back_project(const Eigen::Vector2d& pixel) const {
    return {(pixel.x() - cx_) / fx_, (pixel.y() - cy_) / fy_, 1.0};
  }
  bool in_image(const Eigen::Vector2d& pixel, double margin_px = 0.0) const {
    return pixel.x() >= margin_px && pixel.y() >= margin_px && pixel.x() < width_ - margin_px &&
           pixel.y() < height_ - margin_px;
  }

 private:
  double fx_ = 0, fy_ = 0, cx_ = 0, cy_ = 0;
  int width_ = 0, height_ = 0;
  std::vector<double> distortion_;
  DistortionModel distortion_model_ = DistortionModel::kRadialTangential;
};

}  // namespace kct
