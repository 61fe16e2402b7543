#include "klt_contour_tracker/core/region_cost.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <stdexcept>
#include <string>

#include "klt_contour_tracker/core/motion_model.h"

namespace kct {

RegionCost::RegionCost(std::shared_ptr<const ContourExtractor> extractor,
                       const RegionCueSettings& settings, int band_px, double learning_rate)
    : cue_(extractor, settings),
      renderer_(std::shared_ptr<const Mesh>(extractor, &extractor->mesh())),
      band_px_(band_px),
      learning_rate_(learning_rate) {
  if (band_px < 1)
    throw std::invalid_argument("RegionCost: band_px must be >= 1, got " + std::to_string(band_px));
  if (!(learning_rate > 0.0 && learning_rate <= 1.0))
    throw std::invalid_argument("RegionCost: learning_rate must be in (0, 1], got " +
                                std::to_string(learning_rate));
  const Mesh& mesh = extractor->mesh();
  radius_m_ = mesh.radius_about(mesh.bounding_box_center());
}

void RegionCost::begin_frame(const PoseCostFrame& frame) {
  frame_ = &frame;
  frame_ok_ = histograms_.ready() && !frame.bgr.empty() && frame.bgr.type() == CV_8UC3 &&
              !frame.levels.empty() && frame.bgr.size() == frame.levels[0].gray.size();
  if (frame_ok_) cue_.set_frame(frame.bgr, histograms_, frame.center_object);
  lines_level_ = -1;
}

void RegionCost::linearize(const Pose& object_to_camera, int level) {
  if (!frame_ok_) return;
  const double scale = 1.0 / frame_->levels.at(level).scale;
  const PinholeCamera& camera = frame_->levels[0].camera;
  // The lines are image data along fixed image lines: when no model point moved by more than a
  // quarter of a line pixel since they were placed, placing them again would read the same.
  if (level == lines_level_) {
    const Vector6d motion =
        motion_increment_between(lines_pose_, object_to_camera, frame_->center_object);
    const double depth = std::max(1e-3, (object_to_camera * frame_->center_object).z());
    const double moved_px =
        camera.fx() / depth * (motion.tail<3>().norm() + motion.head<3>().norm() * radius_m_);
    if (moved_px < 0.25 * scale) return;
  }
  // The silhouette at this pose keeps the lines on the outer outline (RegionCue::linearize).
  cue_.linearize(object_to_camera, camera, scale, silhouette(object_to_camera, camera));
  lines_level_ = level;
  lines_pose_ = object_to_camera;
}

double RegionCost::evaluate(const Pose& object_to_camera, Vector6d* gradient,
                            Matrix6d* hessian) const {
  if (!frame_ok_) return 0.0;
  return cue_.evaluate(object_to_camera, gradient, hessian);
}

bool RegionCost::learn(const cv::Mat& bgr, const Pose& object_to_camera,
                       const PinholeCamera& camera) {
  if (bgr.empty() || bgr.type() != CV_8UC3 || bgr.size() != camera.size()) return false;
  return learn(bgr, silhouette(object_to_camera, camera));
}

cv::Mat RegionCost::silhouette(const Pose& object_to_camera, const PinholeCamera& camera) const {
  return renderer_.render_silhouette(object_to_camera, camera);
}

bool RegionCost::learn(const cv::Mat& bgr, const cv::Mat& mask) {
  if (bgr.empty() || bgr.type() != CV_8UC3 || mask.type() != CV_8UC1 || mask.size() != bgr.size())
    return false;
  return histograms_.learn(bgr, mask, band_px_, learning_rate_);
}

}  // namespace kct
