#include "klt_contour_tracker/core/pose_cost.h"

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "klt_contour_tracker/core/elapsed.h"

namespace kct {

Pose apply_pose_increment(const Pose& object_to_camera, const Vector6d& delta,
                          const Eigen::Vector3d& center_object) {
  const Eigen::Vector3d w = delta.head<3>();
  const double angle = w.norm();
  const Eigen::Matrix3d r =
      angle > 0.0 ? Eigen::AngleAxisd(angle, w / angle).toRotationMatrix()
                  : Eigen::Matrix3d::Identity();
  const Eigen::Vector3d center_camera = object_to_camera * center_object;
  Pose pose = Pose::Identity();
  pose.linear() = r * object_to_camera.linear();
  pose.translation() =
      r * (object_to_camera.translation() - center_camera) + center_camera + delta.tail<3>();
  return pose;
}

Matrix26d projection_jacobian(const Eigen::Vector3d& point_camera,
                              const Eigen::Vector3d& center_camera, double fx, double fy) {
  const double inv_z = 1.0 / point_camera.z();
  const double x = point_camera.x() * inv_z, y = point_camera.y() * inv_z;
  // d pixel / d point (2x3).
  Eigen::Matrix<double, 2, 3> dp;
  dp << fx * inv_z, 0.0, -fx * x * inv_z, 0.0, fy * inv_z, -fy * y * inv_z;
  // d point / d w = -[point - centre]_x (the point moves by w x (point - centre)).
  const Eigen::Vector3d r = point_camera - center_camera;
  Eigen::Matrix3d minus_skew;
  minus_skew << 0.0, r.z(), -r.y(), -r.z(), 0.0, r.x(), r.y(), -r.x(), 0.0;
  Matrix26d j;
  j.leftCols<3>() = dp * minus_skew;
  j.rightCols<3>() = dp;
  return j;
}

cv::Mat chromaticity(const cv::Mat& bgr) {
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw std::invalid_argument("chromaticity: bgr must be a non-empty CV_8UC3 image");
  constexpr float kDarkOffset = 30.0f;  // intensity units added to r + g + b
  // One pass per pixel (it runs on every frame's region at every pyramid level; a chain of
  // whole-image OpenCV operations makes a dozen passes).
  const float k1 = static_cast<float>(255.0 / std::sqrt(2.0));
  const float k2 = static_cast<float>(255.0 / std::sqrt(6.0));
  cv::Mat chroma(bgr.size(), CV_32FC2);
  for (int v = 0; v < bgr.rows; ++v) {
    const cv::Vec3b* in = bgr.ptr<cv::Vec3b>(v);
    cv::Vec2f* out = chroma.ptr<cv::Vec2f>(v);
    for (int u = 0; u < bgr.cols; ++u) {
      const float b = in[u][0], g = in[u][1], r = in[u][2];
      const float inverse_intensity = 1.0f / (r + g + b + kDarkOffset);
      out[u] =
          cv::Vec2f(k1 * (r - g) * inverse_intensity, k2 * (r + g - 2.0f * b) * inverse_intensity);
    }
  }
  return chroma;
}

std::vector<PyramidLevel> make_pyramid(const cv::Mat& gray, const PinholeCamera& camera, int levels,
                                       const cv::Mat& bgr) {
  if (gray.empty() || gray.type() != CV_8UC1)
    throw std::invalid_argument("make_pyramid: gray must be a non-empty CV_8UC1 image");
  if (levels < 1) throw std::invalid_argument("make_pyramid: levels must be >= 1");
  if (!bgr.empty() && bgr.size() != gray.size())
    throw std::invalid_argument("make_pyramid: bgr and gray differ in size");
  std::vector<PyramidLevel> pyramid(levels);
  pyramid[0].gray = gray;
  if (!bgr.empty() && bgr.type() != CV_8UC3)
    throw std::invalid_argument("make_pyramid: bgr must be CV_8UC3");
  pyramid[0].bgr = bgr;
  pyramid[0].camera = camera;
  pyramid[0].scale = 1.0;
  for (int l = 1; l < levels; ++l) {
    // cv::pyrDown keeps pixel centres at integer coordinates: level pixel u maps to 2 u below.
    cv::pyrDown(pyramid[l - 1].gray, pyramid[l].gray);
    if (!pyramid[l - 1].bgr.empty()) cv::pyrDown(pyramid[l - 1].bgr, pyramid[l].bgr);
    const double s = pyramid[l - 1].scale * 0.5;
    pyramid[l].scale = s;
    pyramid[l].camera = PinholeCamera(camera.fx() * s, camera.fy() * s, camera.cx() * s,
                                      camera.cy() * s, pyramid[l].gray.cols, pyramid[l].gray.rows);
  }
  return pyramid;
}

void PoseCostSum::add(std::shared_ptr<PoseCost> cue, double weight) {
  if (!cue) throw std::invalid_argument("PoseCostSum::add: cue is null");
  if (!(weight >= 0.0) || !std::isfinite(weight))
    throw std::invalid_argument("PoseCostSum::add: weight of cue '" + cue->name() +
                                "' must be >= 0 and finite, got " + std::to_string(weight));
  terms_.emplace_back(std::move(cue), weight);
  times_.resize(terms_.size());
}

void PoseCostSum::begin_frame(const PoseCostFrame& frame) {
  times_.assign(terms_.size(), CueTimes());
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    if (!(terms_[i].second > 0.0)) continue;
    const auto start = std::chrono::steady_clock::now();
    terms_[i].first->begin_frame(frame);
    times_[i].begin_frame_ms += elapsed_ms(start);
  }
}

void PoseCostSum::linearize(const Pose& object_to_camera, int level) {
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    if (!(terms_[i].second > 0.0)) continue;
    const auto start = std::chrono::steady_clock::now();
    terms_[i].first->linearize(object_to_camera, level);
    times_[i].linearize_ms += elapsed_ms(start);
  }
}

double PoseCostSum::evaluate(const Pose& object_to_camera, Vector6d* gradient,
                             Matrix6d* hessian) const {
  if (gradient) gradient->setZero();
  if (hessian) hessian->setZero();
  double value = 0.0;
  Vector6d g;
  Matrix6d h;
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const auto& [cue, weight] = terms_[i];
    if (!(weight > 0.0) || !cue->active()) continue;
    const auto start = std::chrono::steady_clock::now();
    g.setZero();
    h.setZero();
    value += weight * cue->evaluate(object_to_camera, gradient ? &g : nullptr,
                                    hessian ? &h : nullptr);
    if (gradient) *gradient += weight * g;
    if (hessian) *hessian += weight * h;
    times_[i].evaluate_ms += elapsed_ms(start);
  }
  return value;
}

}  // namespace kct
