#pragma once
/// \file surface_anchor.h
/// 2D image points lifted onto the mesh surface at a known pose (paper Sec. 3.1: "2D keypoints
/// ... are anchored on the 3D model"), shared by the KLT keypoints and the feature relocalizer.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"

namespace kct {

/// Intersects the camera ray through `pixel` (px of `camera`, full resolution) with the plane of
/// the face `face_index` shows at `lookup` (px of the face-index image, which may be a
/// downscaled render). Returns false where no face is seen or the ray grazes the face; else
/// sets `point_object` (object frame, metres). Exact on the triangle, unlike the rasterized depth.
bool anchor_on_surface(const cv::Mat& face_index, const cv::Point2f& lookup,
                       const cv::Point2f& pixel, const Mesh& mesh, const Pose& object_to_camera,
                       const PinholeCamera& camera, Eigen::Vector3d* point_object);

}  // namespace kct
