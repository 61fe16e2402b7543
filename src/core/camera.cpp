#include "klt_contour_tracker/core/camera.h"

#include <opencv2/calib3d.hpp>

#include <cmath>
#include <stdexcept>
#include <string>

namespace kct {

PinholeCamera::PinholeCamera(double fx, double fy, double cx, double cy, int width, int height,
                             std::vector<double> distortion, DistortionModel model)
    : fx_(fx), fy_(fy), cx_(cx), cy_(cy), width_(width), height_(height),
      distortion_(std::move(distortion)), distortion_model_(model) {
  if (!(std::isfinite(fx) && fx > 0 && std::isfinite(fy) && fy > 0))
    throw std::invalid_argument("camera: focal lengths must be finite and > 0 (fx=" +
                                std::to_string(fx) + ", fy=" + std::to_string(fy) + ")");
  if (!(std::isfinite(cx) && std::isfinite(cy)))
    throw std::invalid_argument("camera: principal point must be finite");
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("camera: image size must be > 0 (got " + std::to_string(width) +
                                "x" + std::to_string(height) + ")");
  for (double d : distortion_)
    if (!std::isfinite(d)) throw std::invalid_argument("camera: distortion must be finite");
  if (model == DistortionModel::kEquidistant && distortion_.size() != 4)
    throw std::invalid_argument("camera: the equidistant (fisheye) model needs 4 coefficients, got " +
                                std::to_string(distortion_.size()));
}

PinholeCamera PinholeCamera::from_matrix(const cv::Matx33d& K, int width, int height,
                                         std::vector<double> distortion,
                                         DistortionModel model) {
  return PinholeCamera(K(0, 0), K(1, 1), K(0, 2), K(1, 2), width, height, std::move(distortion),
                       model);
}

cv::Matx33d PinholeCamera::K() const { return {fx_, 0, cx_, 0, fy_, cy_, 0, 0, 1}; }

bool PinholeCamera::has_distortion() const {
  for (double d : distortion_)
    if (d != 0.0) return true;
  return false;
}

void PinholeCamera::undistortion_maps(cv::Mat& map_x, cv::Mat& map_y) const {
  map_x.release();
  map_y.release();
  if (!has_distortion()) return;
  if (distortion_model_ == DistortionModel::kEquidistant)
    cv::fisheye::initUndistortRectifyMap(K(), distortion_, cv::Matx33d::eye(), K(), size(),
                                         CV_32FC1, map_x, map_y);
  else
    cv::initUndistortRectifyMap(K(), distortion_, cv::noArray(), K(), size(), CV_32FC1, map_x,
                                map_y);
}

}  // namespace kct
