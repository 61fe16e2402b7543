#include "klt_contour_tracker/core/contour_energy.h"
#include "klt_contour_tracker/core/bilinear.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace kct {
namespace {

/// Walks the sample points of Eq. 5 and calls visit(point, normal, |grad . n|) for every point
/// kept; returns the sum of the values and the number of points.
template <typename Visitor>
std::pair<double, int> accumulate(const std::vector<ContourSegment>& segments,
                                  const GradientImage& gradient, double spacing_px,
                                  Visitor&& visit) {
  const double x_max = gradient.width() - 2.0, y_max = gradient.height() - 2.0;
  // Bounded work: when the projected contour is longer than kMaxSamples spacings (an absurd
  // focal length or a pose at the camera), the spacing grows so that at most kMaxSamples points
  // plus one per segment are visited.
  double total_length = 0.0;
  for (const ContourSegment& s : segments) {
    const double length = (s.b_px - s.a_px).norm();
    if (std::isfinite(length)) total_length += length;
  }
  spacing_px = std::max(spacing_px, total_length / ContourEnergy::kMaxSamples);
  double sum = 0.0;
  int count = 0;
  for (const ContourSegment& s : segments) {
    const Eigen::Vector2d d = s.b_px - s.a_px;
    const double length = d.norm();
    if (!(length > 1e-9) || !std::isfinite(length)) continue;  // no direction, no normal
    const Eigen::Vector2d normal(-d.y() / length, d.x() / length);
    const int n = std::max(1, static_cast<int>(std::lround(length / spacing_px)));
    const Eigen::Vector2d step = d / n;
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector2d p = s.a_px + (k + 0.5) * step;
      if (!(p.x() >= 1.0 && p.y() >= 1.0 && p.x() <= x_max && p.y() <= y_max)) continue;
      const int x0 = std::min(static_cast<int>(p.x()), gradient.width() - 2);
      const int y0 = std::min(static_cast<int>(p.y()), gradient.height() - 2);
      const double fx = p.x() - x0, fy = p.y() - y0;
      const double value = std::abs(bilinear(gradient.gx, x0, y0, fx, fy) * normal.x() +
                                    bilinear(gradient.gy, x0, y0, fx, fy) * normal.y());
      visit(p, normal, value);
      sum += value;
      ++count;
    }
  }
  return {sum, count};
}

void check_gradient(const GradientImage& gradient) {
  if (gradient.empty() || gradient.gx.type() != CV_32FC1 || gradient.gy.type() != CV_32FC1 ||
      gradient.gx.size() != gradient.gy.size() || gradient.width() < 3 || gradient.height() < 3)
    throw std::invalid_argument(
        "ContourEnergy: gradient must be two CV_32FC1 images of the same size, at least 3x3");
}

}  // namespace

GradientImage GradientImage::compute(const cv::Mat& gray, double blur_sigma_px) {
  if (gray.empty()) throw std::invalid_argument("GradientImage::compute: empty image");
  if (!(blur_sigma_px >= 0.0))
    throw std::invalid_argument("GradientImage::compute: blur_sigma_px must be >= 0");
  cv::Mat single;
  if (gray.type() == CV_8UC3)
    cv::cvtColor(gray, single, cv::COLOR_BGR2GRAY);
  else if (gray.type() == CV_8UC1 || gray.type() == CV_16UC1 || gray.type() == CV_32FC1)
    single = gray;
  else
    throw std::invalid_argument("GradientImage::compute: unsupported image type " +
                                std::to_string(gray.type()) +
                                " (CV_8UC1, CV_8UC3, CV_16UC1 or CV_32FC1)");
  cv::Mat image;
  single.convertTo(image, CV_32F);
  if (blur_sigma_px > 0.0)
    cv::GaussianBlur(image, image, cv::Size(), blur_sigma_px, blur_sigma_px, cv::BORDER_REPLICATE);
  GradientImage gradient;
  // Sobel 3x3 = [1 2 1]^T smoothing x [-1 0 1] difference: weight sum 8 on a unit ramp.
  cv::Sobel(image, gradient.gx, CV_32F, 1, 0, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
  cv::Sobel(image, gradient.gy, CV_32F, 0, 1, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
  return gradient;
}

ContourEnergy::ContourEnergy(std::shared_ptr<const ContourExtractor> extractor, double spacing_px)
    : extractor_(std::move(extractor)), spacing_px_(spacing_px) {
  if (!extractor_) throw std::invalid_argument("ContourEnergy: extractor is null");
  if (!(spacing_px > 0.0) || !std::isfinite(spacing_px))
    throw std::invalid_argument("ContourEnergy: spacing_px must be > 0, got " +
                                std::to_string(spacing_px));
}

ContourEnergy::ContourEnergy(std::shared_ptr<const Mesh> mesh,
                             std::shared_ptr<const VisibilityTable> visibility,
                             double sharp_edge_angle_deg, double spacing_px)
    : ContourEnergy(std::make_shared<const ContourExtractor>(std::move(mesh), std::move(visibility),
                                                             sharp_edge_angle_deg),
                    spacing_px) {}

double ContourEnergy::evaluate(const Pose& object_to_camera, const PinholeCamera& camera,
                               const GradientImage& gradient) const {
  check_gradient(gradient);
  const auto start = std::chrono::steady_clock::now();
  extractor_->extract(object_to_camera, camera, segments_);
  const auto extracted = std::chrono::steady_clock::now();
  const auto [sum, count] =
      accumulate(segments_, gradient, spacing_px_,
                 [](const Eigen::Vector2d&, const Eigen::Vector2d&, double) {});
  const auto end = std::chrono::steady_clock::now();
  extraction_ms_ += std::chrono::duration<double, std::milli>(extracted - start).count();
  evaluation_ms_ += std::chrono::duration<double, std::milli>(end - start).count();
  return count > 0 ? sum / count : 0.0;
}

EnergyDetails ContourEnergy::evaluate_details(const Pose& object_to_camera,
                                              const PinholeCamera& camera,
                                              const GradientImage& gradient) const {
  check_gradient(gradient);
  EnergyDetails details;
  extractor_->extract(object_to_camera, camera, details.segments);
  const auto [sum, count] = accumulate(
      details.segments, gradient, spacing_px_,
      [&](const Eigen::Vector2d& p, const Eigen::Vector2d& n, double value) {
        details.points.push_back(p);
        details.normals.push_back(n);
        details.values.push_back(value);
      });
  details.num_points = count;
  details.energy = count > 0 ? sum / count : 0.0;
  return details;
}

}  // namespace kct
