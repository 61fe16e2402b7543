#include "klt_contour_tracker/ros/ros_conversions.h"

#include <cv_bridge/cv_bridge.h>
#include <image_geometry/pinhole_camera_model.h>
#include <sensor_msgs/distortion_models.h>
#include <sensor_msgs/image_encodings.h>

#include <cmath>
#include <stdexcept>

namespace klt_contour_tracker {
namespace {

namespace enc = sensor_msgs::image_encodings;

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

kct::PinholeCamera camera_from_info(const sensor_msgs::CameraInfo& info) {
  bool k_zero = true;
  for (double v : info.K) k_zero = k_zero && v == 0.0;
  if (k_zero) throw std::invalid_argument("camera_info K is all zero (uncalibrated camera)");
  if (info.width == 0 || info.height == 0)
    throw std::invalid_argument("camera_info has an empty image size");

  image_geometry::PinholeCameraModel model;
  try {
    model.fromCameraInfo(info);
  } catch (const std::exception& e) {
    throw std::invalid_argument(std::string("camera_info rejected by image_geometry: ") + e.what());
  }

  std::vector<double> distortion;
  bool any_distortion = false;
  for (double d : info.D) any_distortion = any_distortion || d != 0.0;
  if (any_distortion) {
    if (info.distortion_model != sensor_msgs::distortion_models::PLUMB_BOB &&
        info.distortion_model != sensor_msgs::distortion_models::RATIONAL_POLYNOMIAL) {
      throw std::invalid_argument("camera_info distortion model '" + info.distortion_model +
                                  "' is not supported (plumb_bob, rational_polynomial)");
    }
    const cv::Mat_<double>& d = model.distortionCoeffs();
    distortion.assign(d.begin(), d.end());
  }
  const cv::Size size = model.reducedResolution();
  try {
    return kct::PinholeCamera::from_matrix(model.intrinsicMatrix(), size.width, size.height,
                                           distortion);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("camera_info K is not a valid pinhole matrix: ") +
                                e.what());
  }
}

bool same_camera(const sensor_msgs::CameraInfo& a, const sensor_msgs::CameraInfo& b) {
  return a.width == b.width && a.height == b.height && a.binning_x == b.binning_x &&
         a.binning_y == b.binning_y && a.roi.x_offset == b.roi.x_offset &&
         a.roi.y_offset == b.roi.y_offset && a.roi.width == b.roi.width &&
         a.roi.height == b.roi.height && a.K == b.K && a.D == b.D &&
         a.distortion_model == b.distortion_model;
}

cv::Mat image_for_tracker(const sensor_msgs::ImageConstPtr& msg) {
  const std::string& encoding = msg->encoding;
  try {
    if (encoding == enc::MONO8 || encoding == enc::BGR8) {
      return cv_bridge::toCvCopy(msg)->image;
    }
    if (encoding == enc::MONO16 || encoding == enc::TYPE_16UC1) {
      cv::Mat mono8;
      cv_bridge::toCvShare(msg)->image.convertTo(mono8, CV_8U, 1.0 / 256.0);
      return mono8;
    }
    if (enc::isColor(encoding) || enc::isBayer(encoding)) {
      return cv_bridge::toCvCopy(msg, enc::BGR8)->image;
    }
    return cv_bridge::toCvCopy(msg, enc::MONO8)->image;
  } catch (const cv_bridge::Exception& e) {
    throw std::runtime_error("cannot convert image encoding '" + encoding + "': " + e.what());
  } catch (const cv::Exception& e) {
    throw std::runtime_error("cannot convert image encoding '" + encoding + "': " + e.what());
  }
}

}  // namespace klt_contour_tracker
