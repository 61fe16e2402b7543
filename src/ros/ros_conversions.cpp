#include "klt_contour_tracker/ros/ros_conversions.h"

#include <cmath>
#include <stdexcept>

namespace klt_contour_tracker {
namespace {

kct::Pose pose_from_parts(double x, double y, double z, double qx, double qy, double qz,
                          double qw) {
  for (double v : {x, y, z, qx, qy, qz, qw}) {
    if (!std::isfinite(v)) throw std::invalid_argument("pose has a non-finite entry");
  }
  const double norm = std::sqrt(qx * qx + qy * qy + qz * qz + qw * qw);
  if (norm < 1e-6) throw std::invalid_argument("pose quaternion has zero norm");
  return kct::pose_from_quaternion(x, y, z, qx, qy, qz, qw);
}

}  // namespace

geometry_msgs::Pose to_pose_msg(const kct::Pose& pose) {
  geometry_msgs::Pose msg;
  const Eigen::Quaterniond q(pose.rotation());
  msg.position.x = pose.translation().x();
  msg.position.y = pose.translation().y();
  msg.position.z = pose.translation().z();
  msg.orientation.x = q.x();
  msg.orientation.y = q.y();
  msg.orientation.z = q.z();
  msg.orientation.w = q.w();
  return msg;
}

kct::Pose from_pose_msg(const geometry_msgs::Pose& msg) {
  return pose_from_parts(msg.position.x, msg.position.y, msg.position.z, msg.orientation.x,
                         msg.orientation.y, msg.orientation.z, msg.orientation.w);
}

geometry_msgs::Transform to_transform_msg(const kct::Pose& pose) {
  const geometry_msgs::Pose p = to_pose_msg(pose);
  geometry_msgs::Transform msg;
  msg.translation.x = p.position.x;
  msg.translation.y = p.position.y;
  msg.translation.z = p.position.z;
  msg.rotation = p.orientation;
  return msg;
}

kct::Pose from_transform_msg(const geometry_msgs::Transform& msg) {
  return pose_from_parts(msg.translation.x, msg.translation.y, msg.translation.z, msg.rotation.x,
                         msg.rotation.y, msg.rotation.z, msg.rotation.w);
}

}  // namespace klt_contour_tracker
