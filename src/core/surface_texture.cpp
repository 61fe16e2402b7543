#include "klt_contour_tracker/core/surface_texture.h"

#include <algorithm>
#include <cmath>
#include <nlopt.hpp>
#include <opencv2/imgproc.hpp>

#include "klt_contour_tracker/core/pose_parametrization.h"
#include "klt_contour_tracker/core/renderer.h"
#include "klt_contour_tracker/core/surface_anchor.h"

namespace kct {
namespace {

/// prepare(): the object's projected diameter in the band-passed image, px.
constexpr double kWorkDiameterPx = 128.0;
/// prepare(): fine and coarse smoothing, shares of the object's projected diameter.
constexpr double kFineShare = 0.01;
constexpr double kCoarseShare = 0.05;
/// A point is compared only when its normal turns at least this far towards the camera (cosine
/// of the angle between the normal and the direction to the eye): grazing points smear.
constexpr double kMinFacingCosine = 0.2;
/// The surface counts as textured when the median point's band-passed colour is at least this
/// far from zero (grey levels, root mean square over the channels).
constexpr double kMinBandMedian = 3.0;
/// The surface has a colour pattern when its points' chromaticity spreads by at least this
/// (root mean square distance from the mean; benchmark objects: textured can and chest
/// 0.20-0.48, uniformly orange toy 0.08-0.10, grey castle 0.01).
constexpr double kMinChromaStd = 0.15;

/// align(): BOBYQA's first step and stopping tolerance, in shares of the bounds.
constexpr double kAlignInitialStep = 0.15;
constexpr double kAlignTolerance = 1e-3;
/// align(): the coarse stage's further smoothing of the band, its pixels (the object spans
/// kWorkDiameterPx there: 4 % of its size; 2 and 4 px left the test's cube 3-15 deg off).
constexpr double kAlignWideSigmaPx = 5.0;

/// Bilinear value of a CV_32FC3 image at a sub-pixel point at least 1 px inside it.
Eigen::Vector3f sample(const cv::Mat& image, double x, double y) {
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float ax = static_cast<float>(x - x0), ay = static_cast<float>(y - y0);
  const cv::Vec3f* row0 = image.ptr<cv::Vec3f>(y0);
  const cv::Vec3f* row1 = image.ptr<cv::Vec3f>(y0 + 1);
  Eigen::Vector3f c;
  for (int k = 0; k < 3; ++k) {
    const float top = (1 - ax) * row0[x0][k] + ax * row0[x0 + 1][k];
    const float bottom = (1 - ax) * row1[x0][k] + ax * row1[x0 + 1][k];
    c[k] = (1 - ay) * top + ay * bottom;
  }
  return c;
}

/// The point of `prepared` a frame pixel maps to; false outside it (1 px margin).
bool to_band(const PreparedFrame& prepared, const Eigen::Vector2d& pixel, double* x, double* y) {
  *x = (pixel.x() - prepared.roi.x) * prepared.scale;
  *y = (pixel.y() - prepared.roi.y) * prepared.scale;
  return *x >= 1.0 && *y >= 1.0 && *x < prepared.band.cols - 2.0 && *y < prepared.band.rows - 2.0;
}

}  // namespace

SurfaceTexture::SurfaceTexture(std::shared_ptr<const Mesh> mesh) : mesh_(std::move(mesh)) {
  diameter_m_ = mesh_->diameter();
  center_object_ = mesh_->bounding_box_center();
}

PreparedFrame SurfaceTexture::prepare(const cv::Mat& bgr, const Pose& object_to_camera,
                                      const PinholeCamera& camera) const {
  PreparedFrame prepared;
  const Eigen::Vector3d center = object_to_camera * center_object_;
  if (bgr.type() != CV_8UC3 || !(center.z() > 1e-3)) return prepared;
  const Eigen::Vector2d c = camera.project(center);
  const double diameter_px = camera.fx() * diameter_m_ / center.z();
  if (!std::isfinite(c.x()) || !std::isfinite(c.y()) || !(diameter_px > 1.0)) return prepared;
  const double radius = std::min(diameter_px, 1e5);
  prepared.roi = cv::Rect(cv::Point(static_cast<int>(std::max(c.x() - radius, -1e5)),
                                    static_cast<int>(std::max(c.y() - radius, -1e5))),
                          cv::Point(static_cast<int>(std::min(c.x() + radius, 1e5)) + 1,
                                    static_cast<int>(std::min(c.y() + radius, 1e5)) + 1)) &
                 cv::Rect(cv::Point(0, 0), bgr.size());
  if (prepared.roi.width < 4 || prepared.roi.height < 4) return prepared;
  prepared.scale = std::min(1.0, kWorkDiameterPx / diameter_px);
  cv::Mat work;
  cv::resize(bgr(prepared.roi), work, cv::Size(), prepared.scale, prepared.scale, cv::INTER_AREA);
  work.convertTo(work, CV_32FC3);
  const double work_diameter_px = diameter_px * prepared.scale;
  cv::Mat fine, coarse;
  const double fine_sigma = std::max(0.5, kFineShare * work_diameter_px);
  const double coarse_sigma = std::max(2.0, kCoarseShare * work_diameter_px);
  cv::GaussianBlur(work, fine, cv::Size(), fine_sigma, fine_sigma, cv::BORDER_REPLICATE);
  cv::GaussianBlur(work, coarse, cv::Size(), coarse_sigma, coarse_sigma, cv::BORDER_REPLICATE);
  prepared.band = fine - coarse;
  prepared.fine = fine;
  return prepared;
}

void SurfaceTexture::learn(const cv::Mat& bgr, const Pose& object_to_camera,
                           const PinholeCamera& camera, int max_points) {
  clear();
  if (bgr.type() != CV_8UC3 || bgr.size() != camera.size() || max_points <= 0) return;
  RenderOptions options;
  options.draw_color = false;
  const cv::Mat face_index = Renderer(mesh_).render(object_to_camera, camera, options).face_index;
  // Points off the outline by twice the coarse smoothing: nearer, the band-passed colours mix
  // in the background.
  const Eigen::Vector3d center = object_to_camera * center_object_;
  if (!(center.z() > 1e-3)) return;
  const int margin_px = 2 + static_cast<int>(2.0 * kCoarseShare * camera.fx() * diameter_m_ / center.z());
  cv::Mat inner;
  cv::erode(face_index >= 0, inner,
            cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * margin_px + 1, 2 * margin_px + 1)));
  const cv::Rect box = cv::boundingRect(inner);
  const int area = cv::countNonZero(inner);
  if (area == 0) return;
  const int step = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(area) / max_points)));
  const PreparedFrame prepared = prepare(bgr, object_to_camera, camera);
  std::vector<Eigen::Vector3f> chroma;
  if (prepared.band.empty()) return;
  for (int v = box.y; v < box.y + box.height; v += step)
    for (int u = box.x; u < box.x + box.width; u += step) {
      if (!inner.at<uchar>(v, u)) continue;
      const cv::Point2f pixel(static_cast<float>(u), static_cast<float>(v));
      Eigen::Vector3d point_object;
      if (!anchor_on_surface(face_index, pixel, pixel, *mesh_, object_to_camera, camera, &point_object))
        continue;
      // The side the camera sees is the outside (an open or inconsistently wound mesh shows
      // either side of a face).
      Eigen::Vector3d normal = mesh_->face_normal(face_index.at<int>(v, u));
      if ((object_to_camera.linear() * normal).dot(object_to_camera * point_object) > 0.0) normal = -normal;
      const Eigen::Vector3d point_camera = object_to_camera * point_object;
      if (-(object_to_camera.linear() * normal).dot(point_camera.normalized()) < kMinFacingCosine) continue;
      double x, y;
      if (!to_band(prepared, camera.project(point_camera), &x, &y)) continue;
      points_object_.push_back(point_object);
      normals_object_.push_back(normal);
      colors_.push_back(sample(prepared.band, x, y));
      // Chromaticity: the colour's departure from grey relative to its brightness (+10 grey
      // levels keeps dark points from dominating), which shading does not change.
      const Eigen::Vector3f c = sample(prepared.fine, x, y);
      chroma.push_back((c.array() - c.mean()).matrix() / (c.mean() + 10.0f));
    }
  if (size() < kMinPoints) return;
  // The typical point's band-passed colour, not the spread over all points: the shading steps at
  // the creases of an untextured object are band-passed too, but only near the creases.
  std::vector<double> magnitudes;
  for (const Eigen::Vector3f& c : colors_) magnitudes.push_back(c.cast<double>().norm() / std::sqrt(3.0));
  std::nth_element(magnitudes.begin(), magnitudes.begin() + magnitudes.size() / 2, magnitudes.end());
  const double median = magnitudes[magnitudes.size() / 2];
  textured_ = median >= kMinBandMedian;
  // The spread of the chromaticity over the surface: a uniformly coloured object shaded by the
  // light keeps its chromaticity (only specular highlights and shadows move it a little).
  Eigen::Vector3f mean_chroma = Eigen::Vector3f::Zero();
  for (const Eigen::Vector3f& c : chroma) mean_chroma += c;
  mean_chroma /= static_cast<float>(chroma.size());
  double chroma_variance = 0.0;
  for (const Eigen::Vector3f& c : chroma) chroma_variance += (c - mean_chroma).squaredNorm();
  color_pattern_ = textured_ && std::sqrt(chroma_variance / chroma.size()) >= kMinChromaStd;
}

TextureShift SurfaceTexture::best_shift(const PreparedFrame& prepared, const Pose& object_to_camera,
                                        const PinholeCamera& camera, double lateral_step_m, int steps,
                                        double depth_step_ratio) const {
  TextureShift best;
  best.agreement.correlation = -1.0;
  const double depth_m = (object_to_camera * center_object_).z();
  for (int iz = -1; iz <= 1; ++iz)
    for (int ix = -steps; ix <= steps; ++ix)
      for (int iy = -steps; iy <= steps; ++iy) {
        if (ix == 0 && iy == 0 && iz == 0) continue;
        const Eigen::Vector3d shift(ix * lateral_step_m, iy * lateral_step_m, iz * depth_step_ratio * depth_m);
        Pose shifted = object_to_camera;
        shifted.translation() += shift;
        const TextureAgreement a = agreement(prepared, shifted, camera);
        // Ties keep the first: the scan order makes the result deterministic.
        if (a.points >= kMinPoints && a.correlation > best.agreement.correlation) {
          best.object_to_camera = shifted;
          best.shift_camera_m = shift;
          best.agreement = a;
        }
      }
  return best;
}

TextureAlignment SurfaceTexture::align(const PreparedFrame& prepared, const Pose& object_to_camera,
                                       const PinholeCamera& camera, double max_turn_rad,
                                       double max_shift_m, int max_evaluations) const {
  TextureAlignment best;
  best.object_to_camera = object_to_camera;
  best.agreement = agreement(prepared, object_to_camera, camera);
  best.evaluations = 1;
  if (best.agreement.points < kMinPoints || !(max_turn_rad > 0.0) || !(max_shift_m > 0.0) ||
      max_evaluations < 2)
    return best;
  // The six pose parameters around the given pose, scaled to [-1, 1] by the bounds. BOBYQA
  // (derivative-free, bounded, a quadratic model): the correlation over a few hundred sampled
  // points is piecewise smooth in the pose, and a numeric gradient would cost 12 agreements.
  const PoseParametrization parametrization(object_to_camera, center_object_);
  struct Problem {
    const SurfaceTexture* self;
    const PreparedFrame* prepared;
    const PinholeCamera* camera;
    const PoseParametrization* parametrization;
    double turn_rad, shift_m;
    TextureAlignment* best;
    Pose pose_of(const double* x) const {
      Vector6d z;
      for (int i = 0; i < 6; ++i) z[i] = x[i] * (i < 3 ? turn_rad : shift_m);
      return parametrization->apply(z);
    }
  };
  const auto objective = [](unsigned, const double* x, double*, void* data) {
    const auto* p = static_cast<const Problem*>(data);
    const Pose pose = p->pose_of(x);
    const TextureAgreement a = p->self->agreement(*p->prepared, pose, *p->camera);
    ++p->best->evaluations;
    if (a.points < kMinPoints) return -1.0;  // too little of the surface shown to compare
    if (a.correlation > p->best->agreement.correlation) {
      p->best->object_to_camera = pose;
      p->best->agreement = a;
    }
    return a.correlation;
  };
  // Maximizes the agreement with `band` from `x` (updated to the end point) in at most
  // `budget` agreements, the best pose into `stage`.
  const auto maximize = [&](const PreparedFrame& band, TextureAlignment& stage, int budget,
                            std::vector<double>& x) {
    if (budget < 2) return;
    Problem problem{this, &band, &camera, &parametrization, max_turn_rad, max_shift_m, &stage};
    nlopt::opt opt(nlopt::LN_BOBYQA, 6);
    opt.set_lower_bounds(std::vector<double>(6, -1.0));
    opt.set_upper_bounds(std::vector<double>(6, 1.0));
    opt.set_max_objective(objective, &problem);
    opt.set_initial_step(kAlignInitialStep);
    opt.set_maxeval(budget);
    opt.set_xtol_rel(kAlignTolerance);
    double value = 0.0;
    try {
      opt.optimize(x, value);
    } catch (const std::exception&) {
      // roundoff_limited and the like: the best point seen is kept.
    }
  };
  // Coarse to fine: first on the band smoothed further, whose correlation peak is wider (a
  // random-textured cube turned 9-15 deg is found from there, not on the band alone), then on
  // the band itself from the coarse stage's best pose, with the rest of the budget.
  PreparedFrame wide = prepared;
  wide.band = cv::Mat();  // its own pixels: the copy shares prepared's
  cv::GaussianBlur(prepared.band, wide.band, cv::Size(), kAlignWideSigmaPx);
  TextureAlignment coarse;
  coarse.object_to_camera = object_to_camera;
  coarse.agreement = agreement(wide, object_to_camera, camera);
  std::vector<double> x(6, 0.0);
  maximize(wide, coarse, max_evaluations / 2 - 1, x);
  best.evaluations += 1 + coarse.evaluations;
  const Vector6d z = parametrization.parameters_of(coarse.object_to_camera);
  for (int i = 0; i < 6; ++i)
    x[i] = std::clamp(z[i] / (i < 3 ? max_turn_rad : max_shift_m), -1.0, 1.0);
  maximize(prepared, best, max_evaluations - best.evaluations, x);
  return best;
}

TextureAgreement SurfaceTexture::agreement(const PreparedFrame& prepared, const Pose& object_to_camera,
                                           const PinholeCamera& camera) const {
  TextureAgreement result;
  if (prepared.band.empty()) return result;
  // Per channel sums of learned (a) and observed (b) colours for the correlation.
  Eigen::Vector3d sa = Eigen::Vector3d::Zero(), sb = sa, saa = sa, sbb = sa, sab = sa;
  int n = 0;
  for (std::size_t i = 0; i < points_object_.size(); ++i) {
    const Eigen::Vector3d p = object_to_camera * points_object_[i];
    if (!(p.z() > 1e-3)) continue;
    const Eigen::Vector3d normal = object_to_camera.linear() * normals_object_[i];
    if (-normal.dot(p.normalized()) < kMinFacingCosine) continue;
    double x, y;
    if (!to_band(prepared, camera.project(p), &x, &y)) continue;
    const Eigen::Vector3d a = colors_[i].cast<double>();
    const Eigen::Vector3d b = sample(prepared.band, x, y).cast<double>();
    sa += a; sb += b;
    saa += a.cwiseProduct(a); sbb += b.cwiseProduct(b); sab += a.cwiseProduct(b);
    ++n;
  }
  result.points = n;
  if (n < kMinPoints) return result;
  const double covariance = (sab - sa.cwiseProduct(sb) / n).sum();
  const double variance_a = (saa - sa.cwiseProduct(sa) / n).sum();
  const double variance_b = (sbb - sb.cwiseProduct(sb) / n).sum();
  if (!(variance_a > 1e-6) || !(variance_b > 1e-6)) return result;
  result.correlation = covariance / std::sqrt(variance_a * variance_b);
  return result;
}

}  // namespace kct
