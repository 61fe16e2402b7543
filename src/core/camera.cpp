#include "klt_contour_tracker/core/camera.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace kct {

PinholeCamera::PinholeCamera(double fx, double fy, double cx, double cy, int width, int height,
                             std::vector<double> distortion)
    : fx_(fx), fy_(fy), cx_(cx), cy_(cy), width_(width), height_(height),
      distortion_(std::move(distortion)) {
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
}

PinholeCamera PinholeCamera::from_matrix(const cv::Matx33d& K, int width, int height,
                                         std::vector<double> distortion) {
  return PinholeCamera(K(0, 0), K(1, 1), K(0, 2), K(1, 2), width, height, std::move(distortion));
}

cv::Matx33d PinholeCamera::K() const { return {fx_, 0, cx_, 0, fy_, cy_, 0, 0, 1}; }

bool PinholeCamera::has_distortion() const {
  for (double d : distortion_)
    if (d != 0.0) return true;
  return false;
}

}  // namespace kct
