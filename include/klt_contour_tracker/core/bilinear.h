#pragma once
/// \file bilinear.h
/// Bilinear sampling of a single-channel float image and its exact derivative, shared by the
/// contour energy (Eq. 5) and its analytic-gradient cost. Written here rather than taken from
/// cv::remap/cv::getRectSubPix: those sample whole patches through a map, while the energy reads
/// one value per contour point in its innermost loop, and the gradient needs the derivative of
/// exactly the interpolation used for the value.

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace kct {

/// Bilinear interpolation of a CV_32F image at (x0 + fx, y0 + fy), 0 <= fx, fy < 1; the caller
/// guarantees 0 <= x0 < cols - 1 and 0 <= y0 < rows - 1.
inline double bilinear(const cv::Mat& image, int x0, int y0, double fx, double fy) {
  const float* r0 = image.ptr<float>(y0) + x0;
  const float* r1 = image.ptr<float>(y0 + 1) + x0;
  const double top = r0[0] + fx * (r0[1] - r0[0]);
  const double bottom = r1[0] + fx * (r1[1] - r1[0]);
  return top + fy * (bottom - top);
}

/// d/dx and d/dy of bilinear() at the same point (exact, constant inside a pixel cell).
inline Eigen::Vector2d bilinear_derivative(const cv::Mat& image, int x0, int y0, double fx,
                                           double fy) {
  const float* r0 = image.ptr<float>(y0) + x0;
  const float* r1 = image.ptr<float>(y0 + 1) + x0;
  return {(1.0 - fy) * (r0[1] - r0[0]) + fy * (r1[1] - r1[0]),
          (1.0 - fx) * (r1[0] - r0[0]) + fx * (r1[1] - r0[1])};
}

}  // namespace kct
