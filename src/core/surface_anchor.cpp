#include "klt_contour_tracker/core/surface_anchor.h"

#include <cmath>

namespace kct {

bool anchor_on_surface(const cv::Mat& face_index, const cv::Point2f& lookup,
                       const cv::Point2f& pixel, const Mesh& mesh, const Pose& object_to_camera,
                       const PinholeCamera& camera, Eigen::Vector3d* point_object) {
  const int u = static_cast<int>(std::lround(lookup.x));
  const int v = static_cast<int>(std::lround(lookup.y));
  if (u < 0 || v < 0 || u >= face_index.cols || v >= face_index.rows) return false;
  const int face = face_index.at<int>(v, u);
  if (face < 0 || face >= static_cast<int>(mesh.faces.size())) return false;
  const Eigen::Vector3i& f = mesh.faces[face];
  const Eigen::Vector3d p0 = object_to_camera * mesh.vertices[f[0]];
  const Eigen::Vector3d normal = object_to_camera.linear() * mesh.face_normal(face);
  const Eigen::Vector3d ray = camera.back_project({pixel.x, pixel.y});
  const double denominator = normal.dot(ray);
  if (std::abs(denominator) < 1e-9) return false;  // the ray grazes the face
  const double depth = normal.dot(p0) / denominator;
  if (!(depth > 0) || !std::isfinite(depth)) return false;
  *point_object = object_to_camera.inverse() * (depth * ray);
  return true;
}

}  // namespace kct
