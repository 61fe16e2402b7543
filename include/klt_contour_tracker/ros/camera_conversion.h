#pragma once
/// \file camera_conversion.h
/// sensor_msgs/CameraInfo -> kct::PinholeCamera (through image_geometry::PinholeCameraModel,
/// binning and ROI honoured) and sensor_msgs/Image -> the 8-bit image the tracker takes.

#include <opencv2/core.hpp>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include "klt_contour_tracker/core/camera.h"

namespace klt_contour_tracker {

/// The camera of the images that arrive with `info`, sized like those images (binning and ROI
/// applied by image_geometry: reducedResolution(), K/P shifted by the ROI and divided by the
/// binning).
/// - input_is_rectified = true (~input_is_rectified, image_proc's image_rect): the 3x3 left
///   block of P, no distortion (P's Tx/Ty of a stereo pair are ignored: the pose is in the
///   image's own optical frame).
/// - false (image_raw): K and D; plumb_bob and rational_polynomial become OpenCV
///   radial-tangential coefficients, equidistant becomes kct::DistortionModel::kEquidistant.
///   The tracker undistorts each frame to the ideal pinhole with the same K.
/// Throws std::invalid_argument with the reason: K (or P) all zero (uncalibrated camera), empty
/// image size, non-finite or invalid intrinsics, an unknown distortion model or a wrong number
/// of coefficients, an ROI outside the image.
kct::PinholeCamera camera_from_info(const sensor_msgs::CameraInfo& info, bool input_is_rectified);

/// True when two CameraInfo messages describe the same camera (size, binning, ROI, K, D, P,
/// distortion model), i.e. the tracker's camera need not be rebuilt; the header is ignored.
bool same_camera(const sensor_msgs::CameraInfo& a, const sensor_msgs::CameraInfo& b);

/// Image message -> image for kct::Tracker: CV_8UC1 (mono8, mono16 / 256) or CV_8UC3 BGR
/// (bgr8, rgb8, bgra8, rgba8 and the 8/16-bit Bayer patterns, demosaiced by cv_bridge), always
/// a copy owning its pixels (the tracker keeps the previous frame for KLT). Throws
/// std::invalid_argument naming the encoding for any other encoding (depth, float, YUV...) or
/// a malformed message.
cv::Mat image_for_tracker(const sensor_msgs::Image& msg);
/// Same as above, for the subscriber's shared pointer.
cv::Mat image_for_tracker(const sensor_msgs::ImageConstPtr& msg);

}  // namespace klt_contour_tracker
