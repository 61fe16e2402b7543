#pragma once
/// \file ros_conversions.h
/// Conversions between ROS messages and the core's pose type. Poses keep the core's
/// convention: `object_to_camera` in the camera optical frame, metres. Camera and image
/// conversions are in camera_conversion.h (included here).

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>

#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/ros/camera_conversion.h"

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

}  // namespace klt_contour_tracker
