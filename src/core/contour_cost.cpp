#include "klt_contour_tracker/core/contour_cost.h"
#include "klt_contour_tracker/core/bilinear.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

namespace kct {
namespace {

constexpr double kMinDepth = 1e-6;  // metres, as the extractor
constexpr double kContrastFactor = 8.0;
constexpr double kReextractFraction = 0.01;

/// Pinhole projection of camera-frame points (level intrinsics).
struct Projection {
  double fx, fy, cx, cy;
  Eigen::Vector2d operator()(const Eigen::Vector3d& p) const {
    return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
  }
};

/// A contour segment's end points (camera frame) projected: its image length and unit normal.
/// False when an end is behind the camera or the projection is degenerate.
bool project_segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Projection& project,
                     double* length, Eigen::Vector2d* normal) {
  if (a.z() <= kMinDepth || b.z() <= kMinDepth) return false;
  const Eigen::Vector2d d = project(b) - project(a);
  *length = d.norm();
  if (!(*length > 1e-9) || !std::isfinite(*length)) return false;
  *normal = Eigen::Vector2d(-d.y(), d.x()) / *length;  // d turned by +90 deg
  return true;
}

/// Where a camera-frame point falls in gradient images covering `roi` (level px): the cell
/// (x0, y0) relative to roi.tl() and the offsets (ax, ay) inside it. False when the point is
/// behind the camera or not at least one pixel inside the region.
struct Cell {
  int x0, y0;
  double ax, ay;
};
bool cell_at(double u, double v, const cv::Rect& roi, Cell* cell) {
  if (!(u >= roi.x + 1.0 && v >= roi.y + 1.0 && u <= roi.x + roi.width - 2.0 &&
        v <= roi.y + roi.height - 2.0))
    return false;
  const double lu = u - roi.x, lv = v - roi.y;
  cell->x0 = std::min(static_cast<int>(lu), roi.width - 2);
  cell->y0 = std::min(static_cast<int>(lv), roi.height - 2);
  cell->ax = lu - cell->x0;
  cell->ay = lv - cell->y0;
  return true;
}
bool cell_of(const Eigen::Vector3d& x, const Projection& project, const cv::Rect& roi, Cell* cell) {
  if (x.z() <= kMinDepth) return false;
  const Eigen::Vector2d p = project(x);
  return cell_at(p.x(), p.y(), roi, cell);
}

/// PoseCostFrame::occlusion_mask looked up at a level's cell (nearest full-resolution pixel).
struct Hidden {
  const cv::Mat& mask;  ///< CV_8UC1 full resolution, or empty
  double to_full;       ///< full-resolution px per level px
  Hidden(const cv::Mat& m, double level_scale) : mask(m), to_full(1.0 / level_scale) {}
  bool operator()(const cv::Rect& roi, const Cell& c) const {
    if (mask.empty()) return false;
    const int u = static_cast<int>((roi.x + c.x0 + c.ax) * to_full + 0.5);
    const int v = static_cast<int>((roi.y + c.y0 + c.ay) * to_full + 0.5);
    return u >= 0 && v >= 0 && u < mask.cols && v < mask.rows && mask.at<uchar>(v, u) != 0;
  }
};

/// A camera-frame point's projection and inverse depth (shifted_energies()); `in_front` false
/// when it is behind the camera (then nothing else is set).
struct Projected {
  double u = 0.0, v = 0.0, inv_z = 0.0;
  bool in_front = false;
};
Projected projected(const Eigen::Vector3d& x, const Projection& project) {
  Projected p;
  if (x.z() <= kMinDepth) return p;
  p.in_front = true;
  p.inv_z = 1.0 / x.z();
  p.u = project.fx * x.x() * p.inv_z + project.cx;
  p.v = project.fy * x.y() * p.inv_z + project.cy;
  return p;
}

}  // namespace

ContourCost::ContourCost(std::shared_ptr<const ContourExtractor> extractor, double spacing_px,
                         double blur_sigma_px, int num_threads, double chroma_weight)
    : extractor_(std::move(extractor)),
      spacing_px_(spacing_px),
      blur_sigma_px_(blur_sigma_px),
      chroma_weight_(chroma_weight),
      edge_width_px_(std::sqrt(blur_sigma_px * blur_sigma_px + 1.0)) {
  if (!extractor_) throw std::invalid_argument("ContourCost: extractor is null");
  center_object_ = extractor_->mesh().bounding_box_center();
  radius_m_ = extractor_->mesh().radius_about(center_object_);
  if (!(spacing_px > 0.0) || !std::isfinite(spacing_px))
    throw std::invalid_argument("ContourCost: spacing_px must be > 0, got " +
                                std::to_string(spacing_px));
  if (!(blur_sigma_px >= 0.0 && blur_sigma_px <= 20.0))
    throw std::invalid_argument("ContourCost: blur_sigma_px must be in [0, 20], got " +
                                std::to_string(blur_sigma_px));
  if (!(chroma_weight >= 0.0) || !std::isfinite(chroma_weight))
    throw std::invalid_argument("ContourCost: chroma_weight must be >= 0 and finite, got " +
                                std::to_string(chroma_weight));
  if (num_threads < 1)
    throw std::invalid_argument("ContourCost: num_threads must be >= 1, got " +
                                std::to_string(num_threads));
  // At most one thread per pyramid level is used; the workers live as long as the cost.
  workers_ = std::make_unique<WorkerThreads>(num_threads);
}

void ContourCost::begin_frame(const PoseCostFrame& frame) {
  if (frame.levels.empty()) throw std::invalid_argument("ContourCost: frame has no levels");
  frame_ = &frame;
  segments_.clear();
  samples_.clear();
  level_ = 0;
  extracted_ = false;

  // Region around the object's projection at the preliminary pose (full-resolution px): the
  // bounding sphere of the mesh, plus its projected radius and 32 px on every side.
  const PinholeCamera& camera = frame.levels[0].camera;
  const Eigen::Vector3d center = frame.predicted_object_to_camera * center_object_;
  cv::Rect2d full(0, 0, camera.width(), camera.height());
  if (center.z() > radius_m_ + kMinDepth) {
    const Eigen::Vector2d c = camera.project(center);
    const double r = std::max(camera.fx(), camera.fy()) * radius_m_ / (center.z() - radius_m_);
    const double half = 2.0 * r + 32.0;
    full = cv::Rect2d(c.x() - half, c.y() - half, 2 * half, 2 * half) &
           cv::Rect2d(0, 0, camera.width(), camera.height());
  }

  // Each level's region (level px): empty when too small to differentiate.
  std::vector<cv::Rect> rois(frame.levels.size());
  for (std::size_t l = 0; l < rois.size(); ++l) {
    const PyramidLevel& level = frame.levels[l];
    rois[l] = cv::Rect(static_cast<int>(std::floor(full.x * level.scale)),
                       static_cast<int>(std::floor(full.y * level.scale)),
                       static_cast<int>(std::ceil(full.width * level.scale)) + 2,
                       static_cast<int>(std::ceil(full.height * level.scale)) + 2) &
              cv::Rect(0, 0, level.gray.cols, level.gray.rows);
    if (rois[l].width < 3 || rois[l].height < 3) rois[l] = cv::Rect();
  }
  // The same pyramid (the same buffers, held by levels_source_) and the same regions: the
  // derivatives are those computed last time.
  bool same = levels_.size() == frame.levels.size() && levels_source_.size() == frame.levels.size();
  for (std::size_t l = 0; same && l < rois.size(); ++l)
    same = levels_source_[l].data == frame.levels[l].gray.data &&
           levels_source_[l].size() == frame.levels[l].gray.size() && levels_[l].roi == rois[l] &&
           levels_[l].chroma_gx[0].empty() ==
               (chroma_level(static_cast<int>(l)) != static_cast<int>(l));
  if (same) return;
  levels_source_.clear();
  levels_.assign(frame.levels.size(), LevelImages());
  workers_->parallel_for(static_cast<int>(frame.levels.size()), [&](int l) {
    const PyramidLevel& level = frame.levels[l];
    LevelImages& out = levels_[l];
    const cv::Rect bounds(0, 0, level.gray.cols, level.gray.rows);
    const cv::Rect roi = rois[l];
    out.roi = roi;
    if (roi.empty()) return;
    // Blur on a slightly larger window so that the region's border is not biased by padding.
    const int pad = static_cast<int>(std::ceil(3.0 * blur_sigma_px_)) + 2;
    const cv::Rect outer =
        cv::Rect(roi.x - pad, roi.y - pad, roi.width + 2 * pad, roi.height + 2 * pad) & bounds;
    const cv::Rect inner(roi.x - outer.x, roi.y - outer.y, roi.width, roi.height);
    // Blurred, then Sobel 3x3 / 8: a ramp of slope s gives s (as GradientImage::compute).
    const auto derivatives = [&](const cv::Mat& source, double scale, cv::Mat* dx, cv::Mat* dy) {
      cv::Mat image;
      source.convertTo(image, CV_32F);
      if (blur_sigma_px_ > 0.0)
        cv::GaussianBlur(image, image, cv::Size(), blur_sigma_px_, blur_sigma_px_,
                         cv::BORDER_REPLICATE);
      cv::Mat gx, gy;
      cv::Sobel(image, gx, CV_32F, 1, 0, 3, scale / 8.0, 0.0, cv::BORDER_REPLICATE);
      cv::Sobel(image, gy, CV_32F, 0, 1, 3, scale / 8.0, 0.0, cv::BORDER_REPLICATE);
      *dx = gx(inner);
      *dy = gy(inner);
    };
    derivatives(level.gray(outer), 1.0, &out.gx, &out.gy);
    cv::Mat magnitude;
    cv::magnitude(out.gx, out.gy, magnitude);
    out.contrast = kContrastFactor * cv::mean(magnitude)[0];
    if (chroma_level(l) == l) {
      // Only the region's chromaticity is computed; both channels are filtered in one call.
      cv::Mat gx2, gy2;
      derivatives(chromaticity(level.bgr(outer)), chroma_weight_, &gx2, &gy2);
      cv::split(gx2, out.chroma_gx);
      cv::split(gy2, out.chroma_gy);
      for (int k = 0; k < 2; ++k) {
        cv::Mat chroma_magnitude;
        cv::magnitude(out.chroma_gx[k], out.chroma_gy[k], chroma_magnitude);
        out.chroma_contrast += kContrastFactor * cv::mean(chroma_magnitude)[0];
      }
    }
  });
  // The contrast scale covers every channel the level reads (its chromaticity's, in this
  // level's px, where it reads a coarser level's).
  for (std::size_t l = 0; l < levels_.size(); ++l) {
    const int at = chroma_level(static_cast<int>(l));
    if (at >= 0)
      levels_[l].contrast +=
          levels_[at].chroma_contrast * frame.levels[at].scale / frame.levels[l].scale;
    levels_[l].contrast = std::max(1e-3, levels_[l].contrast);
  }
  for (const PyramidLevel& level : frame.levels) levels_source_.push_back(level.gray);
}

int ContourCost::chroma_level(int level) const {
  if (!(chroma_weight_ > 0.0) || !frame_ || level < 0 ||
      level >= static_cast<int>(frame_->levels.size()))
    return -1;
  // Colour cameras and their streams carry the chroma at half the resolution (Bayer mosaic,
  // YUV 4:2:0, JPEG): the full-resolution level reads it from the next coarser one.
  const int at = level == 0 && frame_->levels.size() > 1 ? 1 : level;
  return frame_->levels[at].bgr.empty() ? -1 : at;
}

double ContourCost::contrast_scale() const {
  return levels_.empty() ? 1.0 : levels_[level_].contrast;
}

void ContourCost::linearize(const Pose& object_to_camera, int level) {
  if (!frame_ || level < 0 || level >= static_cast<int>(levels_.size()))
    throw std::invalid_argument("ContourCost::linearize: begin_frame() first, level " +
                                std::to_string(level) + " out of range");
  level_ = level;
  segments_.clear();
  samples_.clear();
  if (levels_[level].roi.empty()) return;
  const PinholeCamera& camera = frame_->levels[level].camera;
  const std::vector<MeshEdge>& edges = extractor_->edges();
  const std::vector<Eigen::Vector3d>& vertices = extractor_->mesh().vertices;
  // The edge set (Algorithm 1) is extracted again only when the camera centre, in the object
  // frame, moved by more than kReextractFraction of its distance to the object since the last
  // extraction of this frame (about 0.6 deg): between the optimizer's small steps and from one
  // pyramid level to the next the same edges are re-projected and re-sampled.
  const Eigen::Vector3d camera_object =
      -(object_to_camera.linear().transpose() * object_to_camera.translation());
  const double distance = (camera_object - frame_->center_object).norm();
  if (!extracted_ || !((camera_object - extracted_camera_).norm() <= kReextractFraction * distance)) {
    extractor_->extract(object_to_camera, camera, scratch_);
    extracted_camera_ = camera_object;
    extracted_ = true;
  } else {
    // Re-project the kept edges for this pose and level (as extract() does).
    const Eigen::Matrix3d r = object_to_camera.linear();
    const Eigen::Vector3d t = object_to_camera.translation();
    for (ContourSegment& s : scratch_) {
      const Eigen::Vector3d a = r * vertices[edges[s.edge].v0] + t;
      const Eigen::Vector3d b = r * vertices[edges[s.edge].v1] + t;
      const bool in_front = a.z() > kMinDepth && b.z() > kMinDepth;
      s.a_px = in_front ? camera.project(a) : Eigen::Vector2d::Zero();
      s.b_px = in_front ? camera.project(b) : Eigen::Vector2d::Zero();  // length 0: skipped
    }
  }
  // Points every `step` px along the projected edges taken one after the other (the remainder
  // carried from edge to edge, so that a fine mesh's many short edges are not each given a
  // point of their own), at most kMaxSamples of them: the cost stops growing with the mesh.
  double total_length = 0.0;
  for (const ContourSegment& s : scratch_) {
    const double length = (s.b_px - s.a_px).norm();
    if (length > 1e-9 && std::isfinite(length)) total_length += length;
  }
  if (!(total_length > 0.0)) return;
  const double step = std::max(spacing_px_, total_length / kMaxSamples);
  double next = 0.5 * step;  // distance from the current edge's start to the next point
  for (const ContourSegment& s : scratch_) {
    const double length = (s.b_px - s.a_px).norm();
    if (!(length > 1e-9) || !std::isfinite(length)) continue;
    Segment segment;
    segment.a_object = vertices[edges[s.edge].v0];
    segment.b_object = vertices[edges[s.edge].v1];
    segment.first_sample = static_cast<int>(samples_.size());
    for (; next < length; next += step)
      samples_.push_back(segment.a_object + (next / length) * (segment.b_object - segment.a_object));
    next -= length;
    segment.end_sample = static_cast<int>(samples_.size());
    if (segment.end_sample > segment.first_sample) segments_.push_back(segment);
  }
}

double ContourCost::accumulate(const Pose& object_to_camera, int* count, Vector6d* gradient,
                               Matrix6d* hessian) const {
  const LevelImages& images = levels_[level_];
  const PinholeCamera& camera = frame_->levels[level_].camera;
  const double fx = camera.fx(), fy = camera.fy();
  const Projection project{fx, fy, camera.cx(), camera.cy()};
  const bool derivatives = gradient || hessian;
  const Eigen::Matrix3d r = object_to_camera.linear();
  const Eigen::Vector3d t = object_to_camera.translation();
  const Eigen::Vector3d center_camera = object_to_camera * frame_->center_object;
  const double inv_sigma2 = 1.0 / (edge_width_px_ * edge_width_px_);
  Eigen::Matrix2d perp;
  perp << 0.0, -1.0, 1.0, 0.0;

  const Hidden hidden(frame_->occlusion_mask, frame_->levels[level_].scale);
  const int chroma_at = chroma_level(level_);
  const LevelImages* chroma = chroma_at >= 0 ? &levels_[chroma_at] : nullptr;
  const double to_chroma =
      chroma ? frame_->levels[chroma_at].scale / frame_->levels[level_].scale : 1.0;
  double sum = 0.0;
  int kept = 0;
  for (const Segment& segment : segments_) {
    const Eigen::Vector3d a = r * segment.a_object + t, b = r * segment.b_object + t;
    Eigen::Vector2d normal;
    double length = 0.0;
    if (!project_segment(a, b, project, &length, &normal)) continue;
    Matrix26d normal_jacobian = Matrix26d::Zero();  // d normal / d delta
    if (derivatives) {
      const Matrix26d dd = projection_jacobian(b, center_camera, fx, fy) -
                           projection_jacobian(a, center_camera, fx, fy);
      normal_jacobian =
          (Eigen::Matrix2d::Identity() - normal * normal.transpose()) * perp * dd / length;
    }
    for (int k = segment.first_sample; k < segment.end_sample; ++k) {
      const Eigen::Vector3d x = r * samples_[k] + t;
      Cell c;
      if (!cell_of(x, project, images.roi, &c) || hidden(images.roi, c)) continue;
      // Each channel's |g . n| (and its derivative) at `cell` of its images: the grey one here
      // and, when used, the two chromaticity ones read on their own level (`scale` its px per
      // this level's px: a gradient there is scale x one here, its derivative scale^2 x).
      double value = 0.0;
      const Matrix26d jp =
          derivatives ? projection_jacobian(x, center_camera, fx, fy) : Matrix26d();
      const auto add_channel = [&](const cv::Mat& cgx, const cv::Mat& cgy, const Cell& cell,
                                   double scale) {
        const Eigen::Vector2d g =
            scale * Eigen::Vector2d(bilinear(cgx, cell.x0, cell.y0, cell.ax, cell.ay),
                                    bilinear(cgy, cell.x0, cell.y0, cell.ax, cell.ay));
        const double along = g.dot(normal);
        value += std::abs(along);
        if (!gradient) return;
        // d(g . n)/dp = n^T dg/dp, dg/dp the exact derivative of the bilinear interpolation.
        const double s2 = scale * scale;
        const Eigen::Vector2d dgx =
            s2 * bilinear_derivative(cgx, cell.x0, cell.y0, cell.ax, cell.ay);
        const Eigen::Vector2d dgy =
            s2 * bilinear_derivative(cgy, cell.x0, cell.y0, cell.ax, cell.ay);
        const Eigen::RowVector2d dvalue_dp(normal.x() * dgx.x() + normal.y() * dgy.x(),
                                           normal.x() * dgx.y() + normal.y() * dgy.y());
        const double sign = along >= 0.0 ? 1.0 : -1.0;
        *gradient += sign * (dvalue_dp * jp + g.transpose() * normal_jacobian).transpose();
      };
      add_channel(images.gx, images.gy, c, 1.0);
      Cell chroma_cell;
      if (chroma) {
        const Eigen::Vector2d p = project(x);
        if (cell_at(p.x() * to_chroma, p.y() * to_chroma, chroma->roi, &chroma_cell))
          for (int k = 0; k < 2; ++k)
            add_channel(chroma->chroma_gx[k], chroma->chroma_gy[k], chroma_cell, to_chroma);
      }
      sum += value;
      ++kept;
      if (!derivatives) continue;
      if (hessian) {
        const Eigen::Matrix<double, 1, 6> along_normal = normal.transpose() * jp;
        *hessian += (value * inv_sigma2) * along_normal.transpose() * along_normal;
      }
    }
  }
  if (count) *count = kept;
  return sum;
}

double ContourCost::energy(const Pose& object_to_camera, int* num_points) const {
  if (!frame_ || levels_.empty() || levels_[level_].roi.empty()) {
    if (num_points) *num_points = 0;
    return 0.0;
  }
  int count = 0;
  const double sum = accumulate(object_to_camera, &count, nullptr, nullptr);
  if (num_points) *num_points = count;
  return count > 0 ? sum / count : 0.0;
}

std::vector<double> ContourCost::shifted_energies(const Pose& object_to_camera,
                                                  const std::vector<Eigen::Vector3d>& shifts_camera,
                                                  std::vector<int>* num_points) const {
  for (const Eigen::Vector3d& shift : shifts_camera)
    if (shift.z() != 0.0)
      throw std::invalid_argument(
          "ContourCost::shifted_energies: shifts must be parallel to the image plane (z = 0)");
  std::vector<double> energies(shifts_camera.size(), 0.0);
  if (num_points) num_points->assign(shifts_camera.size(), 0);
  if (!frame_ || levels_.empty() || levels_[level_].roi.empty()) return energies;
  // accumulate() without derivatives. A shift parallel to the image plane keeps every point's
  // depth, so its projection moves by (fx sx, fy sy) / z: the points are projected once for all
  // shifts, and each shift costs a multiply-add per coordinate (not a division).
  const LevelImages& images = levels_[level_];
  const PinholeCamera& camera = frame_->levels[level_].camera;
  const Projection project{camera.fx(), camera.fy(), camera.cx(), camera.cy()};
  const Hidden hidden(frame_->occlusion_mask, frame_->levels[level_].scale);
  const int chroma_at = chroma_level(level_);
  const LevelImages* chroma = chroma_at >= 0 ? &levels_[chroma_at] : nullptr;
  const double to_chroma =
      chroma ? frame_->levels[chroma_at].scale / frame_->levels[level_].scale : 1.0;
  std::vector<Projected> ends(2 * segments_.size()), samples(samples_.size());
  for (std::size_t i = 0; i < segments_.size(); ++i) {
    ends[2 * i] = projected(object_to_camera * segments_[i].a_object, project);
    ends[2 * i + 1] = projected(object_to_camera * segments_[i].b_object, project);
  }
  for (std::size_t k = 0; k < samples_.size(); ++k)
    samples[k] = projected(object_to_camera * samples_[k], project);
  for (std::size_t s = 0; s < shifts_camera.size(); ++s) {
    const double du = project.fx * shifts_camera[s].x(), dv = project.fy * shifts_camera[s].y();
    double sum = 0.0;
    int kept = 0;
    for (std::size_t i = 0; i < segments_.size(); ++i) {
      const Projected& a = ends[2 * i];
      const Projected& b = ends[2 * i + 1];
      if (!a.in_front || !b.in_front) continue;
      // As project_segment() on the shifted ends.
      const Eigen::Vector2d d(b.u - a.u + du * (b.inv_z - a.inv_z),
                              b.v - a.v + dv * (b.inv_z - a.inv_z));
      const double length = d.norm();
      if (!(length > 1e-9) || !std::isfinite(length)) continue;
      const Eigen::Vector2d normal = Eigen::Vector2d(-d.y(), d.x()) / length;
      const Segment& segment = segments_[i];
      for (int k = segment.first_sample; k < segment.end_sample; ++k) {
        const Projected& q = samples[static_cast<std::size_t>(k)];
        Cell c;
        if (!q.in_front || !cell_at(q.u + du * q.inv_z, q.v + dv * q.inv_z, images.roi, &c) ||
            hidden(images.roi, c))
          continue;
        sum += std::abs(bilinear(images.gx, c.x0, c.y0, c.ax, c.ay) * normal.x() +
                        bilinear(images.gy, c.x0, c.y0, c.ax, c.ay) * normal.y());
        Cell cc;
        if (chroma && cell_at((q.u + du * q.inv_z) * to_chroma, (q.v + dv * q.inv_z) * to_chroma,
                              chroma->roi, &cc))
          for (int k = 0; k < 2; ++k)
            sum +=
                to_chroma *
                std::abs(bilinear(chroma->chroma_gx[k], cc.x0, cc.y0, cc.ax, cc.ay) * normal.x() +
                         bilinear(chroma->chroma_gy[k], cc.x0, cc.y0, cc.ax, cc.ay) * normal.y());
        ++kept;
      }
    }
    energies[s] = kept > 0 ? sum / kept : 0.0;
    if (num_points) (*num_points)[s] = kept;
  }
  return energies;
}

double ContourCost::evaluate(const Pose& object_to_camera, Vector6d* gradient,
                             Matrix6d* hessian) const {
  if (!frame_ || levels_.empty() || levels_[level_].roi.empty()) return 0.0;
  Vector6d g = Vector6d::Zero();
  Matrix6d h = Matrix6d::Zero();
  int count = 0;
  const double sum = accumulate(object_to_camera, &count, gradient ? &g : nullptr,
                                hessian ? &h : nullptr);
  if (count == 0) return 0.0;
  const double scale = 1.0 / (count * levels_[level_].contrast);
  if (gradient) *gradient -= scale * g;  // cost = -E / c
  if (hessian) *hessian += scale * h;
  return -sum * scale;
}

}  // namespace kct
