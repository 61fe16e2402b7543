#include "klt_contour_tracker/core/debug_drawing.h"

#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace kct {
namespace {

const cv::Scalar kContourColour(0, 255, 0);
const cv::Scalar kSharpColour(0, 220, 255);
const cv::Scalar kKeypointColour(255, 255, 0);

cv::Point2d to_cv(const Eigen::Vector2d& p) { return {p.x(), p.y()}; }

void draw_axes(cv::Mat& canvas, const Pose& pose, const PinholeCamera& camera, double length_m) {
  const Eigen::Vector3d origin = pose.translation();
  if (origin.z() <= 1e-3) return;
  const cv::Scalar colours[3] = {{0, 0, 255}, {0, 255, 0}, {255, 0, 0}};
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d tip = pose * (length_m * Eigen::Vector3d::Unit(axis));
    if (tip.z() <= 1e-3) continue;
    cv::line(canvas, to_cv(camera.project(origin)), to_cv(camera.project(tip)), colours[axis], 2,
             cv::LINE_AA);
  }
}

}  // namespace

cv::Mat draw_tracking_overlay(const cv::Mat& image, const TrackResult& result,
                              const PinholeCamera& camera, const Mesh& mesh, double diameter_m,
                              const ContourExtractor* extractor, const std::string& label) {
  cv::Mat canvas;
  if (image.channels() == 1)
    cv::cvtColor(image, canvas, cv::COLOR_GRAY2BGR);
  else
    canvas = image.clone();
  const bool has_pose = result.status != TrackStatus::kNotInitialized &&
                        result.status != TrackStatus::kInvalidInput;
  if (has_pose) {
    const Pose& pose = result.object_to_camera;
    if (extractor) {
      for (const ContourSegment& s : extractor->extract(pose, camera))
        cv::line(canvas, to_cv(s.a_px), to_cv(s.b_px),
                 s.type == EdgeType::kContour ? kContourColour : kSharpColour, 1, cv::LINE_AA);
    } else {
      // Without the refiner's visibility data: every edge whose faces meet at > 45 deg.
      for (const MeshEdge& e : mesh.shared_edges()) {
        if (mesh.face_normal(e.face0).dot(mesh.face_normal(e.face1)) > 0.7071) continue;
        const Eigen::Vector3d a = pose * mesh.vertices[e.v0], b = pose * mesh.vertices[e.v1];
        if (a.z() <= 1e-3 || b.z() <= 1e-3) continue;
        cv::line(canvas, to_cv(camera.project(a)), to_cv(camera.project(b)), kSharpColour, 1,
                 cv::LINE_AA);
      }
    }
    for (const Eigen::Vector2d& p : result.keypoints.inlier_points.points_image)
      cv::drawMarker(canvas, to_cv(p), kKeypointColour, cv::MARKER_CROSS, 5, 1);
    draw_axes(canvas, pose, camera, 0.3 * diameter_m);
  }
  char text[256];
  std::snprintf(text, sizeof(text), "%s%s%s | KLT %d/%d | E %.1f -> %.1f | hops %d | %.0f ms",
                to_string(result.status), label.empty() ? "" : " ", label.c_str(),
                result.keypoints.inliers, result.keypoints.tracked, result.energy_before,
                result.energy_after, result.hops, result.frame_time_ms);
  cv::rectangle(canvas, {0, 0}, {canvas.cols, 22}, cv::Scalar(0, 0, 0), cv::FILLED);
  cv::putText(canvas, text, {6, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
  return canvas;
}

}  // namespace kct
