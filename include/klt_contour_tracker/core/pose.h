#pragma once
/// \file pose.h
/// SE(3) pose type and helpers. Convention used everywhere in the package: a pose named
/// `object_to_camera` maps a point given in the object (model) frame into the camera
/// optical frame (x right, y down, z forward; REP 103 optical frame): x_cam = T * x_obj.
/// Translations are in metres (the model's units after `mesh_scale`).

#include <Eigen/Geometry>
#include <array>

namespace kct {

/// Rigid transform; see the file comment for the frame convention.
using Pose = Eigen::Isometry3d;

/// True when every entry is finite and the rotation block is orthonormal within 1e-6.
bool is_valid_pose(const Pose& pose);

/// Constant-velocity extrapolation of frame i from frames i-2 and i-1 (paper Sec. 3.1):
/// the camera-frame motion between i-2 and i-1 is applied once more to i-1.
Pose extrapolate_pose(const Pose& object_to_camera_i2, const Pose& object_to_camera_i1);

/// Angle of the relative rotation between two poses, in degrees, in [0, 180].
double rotation_error_deg(const Pose& a, const Pose& b);

/// Distance between the translations of two poses, in the poses' units.
double translation_error(const Pose& a, const Pose& b);

/// Pose from 12 numbers: the rotation row-major then the translation (the pose.txt format).
Pose pose_from_row(const std::array<double, 12>& row);

/// The 12 numbers of pose_from_row() for a pose.
std::array<double, 12> pose_to_row(const Pose& pose);

/// Rotation from a unit quaternion given as x, y, z, w (normalized here) and a translation.
Pose pose_from_quaternion(double x, double y, double z, double qx, double qy, double qz, double qw);

}  // namespace kct
