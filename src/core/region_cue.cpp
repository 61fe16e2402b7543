#include "klt_contour_tracker/core/region_cue.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace kct {
namespace {

constexpr double kMinDepth = 1e-6;  // metres
// Distance from a line's centre at which the rendered silhouette is trusted, px: past the
// rasterization's half-pixel uncertainty of where the edge falls.
constexpr double kProbePx = 1.5;

/// The silhouette's pixel nearest to `p`, or null outside the image.
const uchar* silhouette_pixel(const cv::Mat& silhouette, const Eigen::Vector2d& p) {
  const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
  if (x < 0 || y < 0 || x >= silhouette.cols || y >= silhouette.rows) return nullptr;
  return &silhouette.at<uchar>(y, x);
}

/// The vertex of `face` that is neither end of the edge (v0, v1); -1 if none.
int opposite_vertex(const Mesh& mesh, int face, int v0, int v1) {
  for (int k = 0; k < 3; ++k) {
    const int v = mesh.faces[face][k];
    if (v != v0 && v != v1) return v;
  }
  return -1;
}

}  // namespace

RegionCue::RegionCue(std::shared_ptr<const ContourExtractor> extractor,
                     const RegionCueSettings& settings)
    : extractor_(std::move(extractor)), settings_(settings) {
  if (!extractor_) throw std::invalid_argument("RegionCue: extractor is null");
  if (settings.line_half_length_px < 2 || settings.line_half_length_px > 100)
    throw std::invalid_argument("RegionCue: line_half_length_px must be in [2, 100], got " +
                                std::to_string(settings.line_half_length_px));
  if (!(settings.line_spacing_px > 0.0) || !std::isfinite(settings.line_spacing_px))
    throw std::invalid_argument("RegionCue: line_spacing_px must be > 0");
  if (!(settings.step_slope_px > 0.0) || !std::isfinite(settings.step_slope_px))
    throw std::invalid_argument("RegionCue: step_slope_px must be > 0");
  if (!(settings.step_amplitude > 0.0 && settings.step_amplitude < 0.5))
    throw std::invalid_argument("RegionCue: step_amplitude must be in (0, 0.5)");
  // alpha_h tanh((j - k + 0.5) / (2 s_h)) for j - k in [-(2L - 1), 2L - 1] (offset units).
  const int half = settings.line_half_length_px;
  for (int m = -(2 * half - 1); m <= 2 * half - 1; ++m)
    step_table_.push_back(settings.step_amplitude *
                          std::tanh((m + 0.5) / (2.0 * settings.step_slope_px)));
}

void RegionCue::set_frame(const cv::Mat& bgr, const ColorHistograms& histograms,
                          const Eigen::Vector3d& center_object) {
  if (bgr.type() != CV_8UC3 || bgr.cols < 2 || bgr.rows < 2)
    throw std::invalid_argument("RegionCue::set_frame: bgr must be CV_8UC3, at least 2x2");
  bgr_ = bgr;
  histograms_ = &histograms;
  center_object_ = center_object;
  posterior_cache_.create(bgr.size(), CV_32F);
  posterior_cache_.setTo(-1.0f);
  lines_.clear();
  contrast_.clear();
}

float RegionCue::pixel_posterior(int x, int y) const {
  float& cached = posterior_cache_.at<float>(y, x);
  if (cached < 0.0f) cached = histograms_->posterior(bgr_.at<cv::Vec3b>(y, x));
  return cached;
}

double RegionCue::posterior_at(double x, double y) const {
  if (!(x >= 0.0 && y >= 0.0 && x <= bgr_.cols - 1.0 && y <= bgr_.rows - 1.0)) return 0.5;
  const int x0 = std::min(static_cast<int>(x), bgr_.cols - 2);
  const int y0 = std::min(static_cast<int>(y), bgr_.rows - 2);
  const double fx = x - x0, fy = y - y0;
  const double p00 = pixel_posterior(x0, y0), p10 = pixel_posterior(x0 + 1, y0);
  const double p01 = pixel_posterior(x0, y0 + 1), p11 = pixel_posterior(x0 + 1, y0 + 1);
  const double top = p00 + fx * (p10 - p00), bottom = p01 + fx * (p11 - p01);
  return top + fy * (bottom - top);
}

void RegionCue::linearize(const Pose& object_to_camera, const PinholeCamera& camera, double scale,
                          const cv::Mat& silhouette) {
  if (!histograms_) throw std::logic_error("RegionCue::linearize: set_frame() was not called");
  if (!(scale >= 1.0) || !std::isfinite(scale))
    throw std::invalid_argument("RegionCue::linearize: scale must be >= 1");
  if (!silhouette.empty() &&
      (silhouette.type() != CV_8UC1 || silhouette.cols != camera.width() ||
       silhouette.rows != camera.height()))
    throw std::invalid_argument("RegionCue::linearize: silhouette must be CV_8UC1 of the camera's size");
  camera_ = camera;
  scale_ = scale;
  lines_.clear();
  contrast_.clear();
  const Mesh& mesh = extractor_->mesh();
  const Pose& pose = object_to_camera;
  extractor_->extract(pose, camera, segments_);
  const Eigen::Vector3d camera_object = -(pose.linear().transpose() * pose.translation());
  const double spacing = settings_.line_spacing_px * scale;

  for (const ContourSegment& segment : segments_) {
    if (segment.type != EdgeType::kContour) continue;  // silhouette only
    const MeshEdge& edge = extractor_->edges()[segment.edge];
    // The face on the object's side of the outline: the front-facing one.
    int front = -1, front_count = 0;
    for (const int face : {edge.face0, edge.face1}) {
      if (face < 0) continue;
      const Eigen::Vector3d n = mesh.face_normal(face);
      if (n.dot(camera_object - mesh.vertices[mesh.faces[face][0]]) > 0.0) {
        front = face;
        ++front_count;
      }
    }
    if (front_count != 1) continue;
    const int inner = opposite_vertex(mesh, front, edge.v0, edge.v1);
    if (inner < 0) continue;
    const Eigen::Vector3d inner_camera = pose * mesh.vertices[inner];
    if (inner_camera.z() <= kMinDepth) continue;
    const Eigen::Vector2d d = segment.b_px - segment.a_px;
    const double length = d.norm();
    if (!(length > 1e-9) || !std::isfinite(length)) continue;
    Eigen::Vector2d normal(-d.y() / length, d.x() / length);
    const double side = normal.dot(camera.project(inner_camera) - segment.a_px);
    if (side == 0.0 || !std::isfinite(side)) continue;
    if (side > 0.0) normal = -normal;  // outward: away from the front face

    const Eigen::Vector3d& a_object = mesh.vertices[edge.v0];
    const Eigen::Vector3d& b_object = mesh.vertices[edge.v1];
    const int count = std::max(1, static_cast<int>(std::lround(length / spacing)));
    for (int k = 0; k < count; ++k) {
      const double t = (k + 0.5) / count;
      Line line;
      line.point_object = a_object + t * (b_object - a_object);
      const Eigen::Vector3d point_camera = pose * line.point_object;
      if (point_camera.z() <= kMinDepth) continue;
      line.centre_px = camera.project(point_camera);
      line.normal = normal;
      if (!silhouette.empty()) {
        const uchar* outside = silhouette_pixel(silhouette, line.centre_px + kProbePx * normal);
        if (outside && *outside != 0) continue;  // the object again: not the outer outline
      }
      place_line(line, scale, silhouette);
      lines_.push_back(line);
    }
  }
}

void RegionCue::place_line(Line& line, double scale, const cv::Mat& silhouette) {
  const int half = settings_.line_half_length_px;
  contrast_.assign(2 * half, 0.0);
  bool informative = false;
  // Outwards from the centre (j >= 0) until the object is met again, inwards (j < 0) until it
  // is left; pixels beyond stay 0 (unknown).
  for (const int direction : {1, -1}) {
    for (int j = direction > 0 ? 0 : -1; j >= -half && j < half; j += direction) {
      const Eigen::Vector2d p = line.centre_px + (j + 0.5) * scale * line.normal;
      // Within kProbePx of the centre the rasterized silhouette's edge is uncertain.
      if (!silhouette.empty() && std::abs(j + 0.5) * scale > kProbePx) {
        const uchar* pixel = silhouette_pixel(silhouette, p);
        if (pixel && (*pixel != 0) != (direction < 0)) break;
      }
      contrast_[j + half] = 2.0 * posterior_at(p.x(), p.y()) - 1.0;
      informative = informative || contrast_[j + half] != 0.0;
    }
  }
  line.mean_px = 0.0;
  line.weight = 0.0;
  if (!informative) return;
  // log p(d) for d = k scale, |k| < L: sum over the line's pixels (SRT3D Eq. 7-9).
  log_likelihood_.clear();
  double best = -std::numeric_limits<double>::infinity();
  for (int k = -(half - 1); k <= half - 1; ++k) {
    double sum = 0.0;
    // alpha tanh(k_step (j + 0.5 - k)) from the table, index j - k + 2 half - 1.
    const double* step = step_table_.data() + (2 * half - 1) - k;
    for (int j = -half; j < half; ++j) {
      const double c = contrast_[j + half];
      if (c != 0.0) sum += std::log(0.5 - step[j] * c);
    }
    log_likelihood_.push_back(sum);
    best = std::max(best, sum);
  }
  double total = 0.0, mean = 0.0, second = 0.0;
  for (std::size_t i = 0; i < log_likelihood_.size(); ++i) {
    const double d = (static_cast<int>(i) - (half - 1)) * scale;
    const double p = std::exp(log_likelihood_[i] - best);
    total += p;
    mean += p * d;
    second += p * d * d;
  }
  mean /= total;
  const double min_variance = 0.25 * scale * scale;
  const double variance = std::max(second / total - mean * mean, min_variance);
  // Variance of a uniform p over the 2L - 1 offsets: a line that tells nothing weighs 0.
  const double n = 2.0 * half - 1.0;
  const double uniform_variance = scale * scale * (n * n - 1.0) / 12.0;
  line.mean_px = mean;
  line.weight = std::max(0.0, 1.0 / variance - 1.0 / uniform_variance);
}

double RegionCue::evaluate(const Pose& object_to_camera, Vector6d* gradient,
                           Matrix6d* hessian) const {
  if (lines_.empty()) return 0.0;
  const double norm = 1.0 / static_cast<double>(lines_.size());
  const Eigen::Vector3d center_camera = object_to_camera * center_object_;
  double sum = 0.0;
  for (const Line& line : lines_) {
    if (line.weight <= 0.0) continue;
    const Eigen::Vector3d point_camera = object_to_camera * line.point_object;
    if (point_camera.z() <= kMinDepth) continue;
    const double delta = line.normal.dot(camera_.project(point_camera) - line.centre_px);
    const double error = delta - line.mean_px;
    sum += 0.5 * line.weight * error * error;
    if (gradient || hessian) {
      const Eigen::Matrix<double, 1, 6> a =
          line.normal.transpose() *
          projection_jacobian(point_camera, center_camera, camera_.fx(), camera_.fy());
      if (gradient) *gradient += (norm * line.weight * error) * a.transpose();
      if (hessian) *hessian += (norm * line.weight) * a.transpose() * a;
    }
  }
  return sum * norm;
}

double RegionCue::cost_at(const Pose& object_to_camera, const PinholeCamera& camera, double scale,
                          const cv::Mat& silhouette) {
  linearize(object_to_camera, camera, scale, silhouette);
  return evaluate(object_to_camera, nullptr, nullptr);
}

}  // namespace kct
