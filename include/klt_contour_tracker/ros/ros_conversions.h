#pragma once
/// \file ros_conversions.h
/// Conversions between ROS messages and the core's types (kct::Pose, kct::PinholeCamera,
/// cv::Mat images). Poses keep the core's convention: `object_to_camera` in the camera optical
/// frame, metres.

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <opencv2/core.hpp>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <string>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/pose.h"

namespace klt_contour_tracker {

/// kct::Pose -> geometry_msgs/Pose (position in metres, unit quaternion).
geometry_msgs::Pose to_pose_msg(const kct::Pose& pose);

/// geometry_msgs/Pose -> kct::Pose; the quaternion is normalized. Throws std::invalid_argument
/// for a non-finite entry or a quaternion of (near) zero norm.
kct::Pose from_pose_msg(const geometry_msgs::Pose& msg);

/// kct::Pose -> geometry_msgs/Transform (the same rigid transform, for tf).
geometry_msgs::Transform to_transform_msg(const kct::Pose& pose);

/// geometry_msgs/Transform -> kct::Pose; same checks as from_pose_msg().
kct::Pose from_transform_msg(const geometry_msgs::Transform& msg);

/// CameraInfo -> pinhole camera through image_geometry::PinholeCameraModel: K and the image
/// size of the (binned/ROI-reduced) image, plus the plumb_bob / rational_polynomial distortion
/// coefficients when any is non-zero. Throws std::invalid_argument when K is all zero or not a
/// valid pinhole matrix, the size is empty, or the distortion model is not supported.
kct::PinholeCamera camera_from_info(const sensor_msgs::CameraInfo& info);

/// True when two CameraInfo messages describe the same camera (size, binning, ROI, K, D,
/// distortion model); the header is ignored.
bool same_camera(const sensor_msgs::CameraInfo& a, const sensor_msgs::CameraInfo& b);

/// Image message -> 8-bit image for the tracker (CV_8UC1 or CV_8UC3 BGR), always a copy owning
/// its pixels (the tracker keeps the previous frame for KLT). mono8/bgr8 pass through; rgb8/rgba8/bgra8 and Bayer
/// patterns become bgr8; mono16/16UC1 are scaled to mono8 (value / 256). Throws
/// std::runtime_error naming the encoding when cv_bridge cannot convert it.
cv::Mat image_for_tracker(const sensor_msgs::ImageConstPtr& msg);

}  // namespace klt_contour_tracker
