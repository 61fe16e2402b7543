#include "klt_contour_tracker/ros/camera_conversion.h"

#include <cv_bridge/cv_bridge.h>
#include <image_geometry/pinhole_camera_model.h>
#include <sensor_msgs/distortion_models.h>
#include <sensor_msgs/image_encodings.h>

#include <boost/endian/conversion.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "klt_contour_tracker/core/plausibility.h"

namespace klt_contour_tracker {
namespace {

namespace enc = sensor_msgs::image_encodings;
namespace dm = sensor_msgs::distortion_models;

[[noreturn]] void reject(const std::string& reason) {
  throw std::invalid_argument("camera_info: " + reason);
}

template <typename Range>
bool all_zero(const Range& values) {
  return std::all_of(std::begin(values), std::end(values), [](double v) { return v == 0.0; });
}

template <typename Range>
void require_finite(const Range& values, const char* name) {
  for (double v : values)
    if (!std::isfinite(v)) reject(std::string(name) + " has a non-finite entry");
}

// Coefficient counts OpenCV's radial-tangential model accepts (k1 k2 p1 p2 [k3 [k4 k5 k6
// [s1..s4 [tx ty]]]]).
bool opencv_coefficient_count(std::size_t n) {
  return n == 4 || n == 5 || n == 8 || n == 12 || n == 14;
}

}  // namespace

kct::PinholeCamera camera_from_info(const sensor_msgs::CameraInfo& info, bool input_is_rectified) {
  // Sizes are unsigned in the message: checked as such before any conversion to int.
  const std::string size_error = kct::implausible_image_size(info.width, info.height, 0);
  if (!size_error.empty()) reject(size_error);
  require_finite(info.K, "K");
  require_finite(info.P, "P");
  require_finite(info.D, "D");
  if (all_zero(info.K)) reject("K is all zero: the camera is not calibrated");
  if (input_is_rectified && all_zero(info.P))
    reject("P is all zero (no rectified projection); for unrectified images set "
           "~input_is_rectified to false to use K and D");
  // The image's size: the raw ROI (all zero = the full image) divided by the binning, as the
  // driver produces it (image_geometry's reducedResolution() would use the rectified ROI when
  // roi.do_rectify is set, which is not the size of the image that arrives).
  const auto& roi = info.roi;
  const bool full = roi.x_offset == 0 && roi.y_offset == 0 && roi.width == 0 && roi.height == 0;
  const std::string roi_text = std::to_string(roi.width) + "x" + std::to_string(roi.height) + "+" +
                               std::to_string(roi.x_offset) + "+" + std::to_string(roi.y_offset);
  if (!full && (roi.width == 0 || roi.height == 0)) reject("ROI " + roi_text + " is empty");
  if (static_cast<std::uint64_t>(roi.x_offset) + roi.width > info.width ||
      static_cast<std::uint64_t>(roi.y_offset) + roi.height > info.height)
    reject("ROI " + roi_text + " lies outside the " + std::to_string(info.width) + "x" +
           std::to_string(info.height) + " image");
  const std::uint32_t binning_x = info.binning_x ? info.binning_x : 1;
  const std::uint32_t binning_y = info.binning_y ? info.binning_y : 1;
  const std::uint32_t reduced_width = (full ? info.width : roi.width) / binning_x;
  const std::uint32_t reduced_height = (full ? info.height : roi.height) / binning_y;
  const std::string reduced_error = kct::implausible_image_size(reduced_width, reduced_height, 0);
  if (!reduced_error.empty())
    reject("with ROI " + roi_text + " and binning " + std::to_string(binning_x) + "x" +
           std::to_string(binning_y) + ", " + reduced_error);
  const int width = static_cast<int>(reduced_width);
  const int height = static_cast<int>(reduced_height);

  std::vector<double> distortion;
  kct::DistortionModel model = kct::DistortionModel::kRadialTangential;
  if (!input_is_rectified && !all_zero(info.D)) {
    const std::size_t n = info.D.size();
    const std::string& name = info.distortion_model;
    if (name == dm::PLUMB_BOB || name == dm::RATIONAL_POLYNOMIAL) {
      if (!opencv_coefficient_count(n))
        reject("distortion model '" + kct::truncate_for_message(name) + "' with " + std::to_string(n) +
               " coefficients (OpenCV takes 4, 5, 8, 12 or 14)");
    } else if (name == dm::EQUIDISTANT) {
      if (n != 4)
        reject("distortion model 'equidistant' needs 4 coefficients, got " + std::to_string(n));
      model = kct::DistortionModel::kEquidistant;
    } else {
      reject("unsupported distortion model '" + kct::truncate_for_message(name) +
             "' (supported: plumb_bob, rational_polynomial, equidistant)");
    }
    distortion.assign(info.D.begin(), info.D.end());
  }

  // image_geometry applies binning and ROI to K and P (intrinsicMatrix(), projectionMatrix()).
  // Those do not depend on D, and its distortion handling (rectified ROI, unknown models) is not
  // used here, so it gets a copy without distortion.
  sensor_msgs::CameraInfo reduced_input = info;
  reduced_input.distortion_model = dm::PLUMB_BOB;
  reduced_input.D.assign(5, 0.0);
  image_geometry::PinholeCameraModel camera_model;
  try {
    camera_model.fromCameraInfo(reduced_input);
  } catch (const std::exception& e) {
    reject(std::string("rejected by image_geometry: ") + e.what());
  }
  cv::Matx33d K = camera_model.intrinsicMatrix();
  if (input_is_rectified) {
    const cv::Matx34d& P = camera_model.projectionMatrix();
    K = cv::Matx33d(P(0, 0), P(0, 1), P(0, 2), P(1, 0), P(1, 1), P(1, 2), P(2, 0), P(2, 1), P(2, 2));
  }
  const char* matrix = input_is_rectified ? "P" : "K";
  if (K(0, 1) != 0.0 || K(1, 0) != 0.0 || K(2, 0) != 0.0 || K(2, 1) != 0.0 || K(2, 2) != 1.0)
    reject(std::string(matrix) + " is not a pinhole matrix [fx 0 cx; 0 fy cy; 0 0 1] (skew or a "
           "non-unit last row)");
  const std::string implausible = kct::implausible_intrinsics(K(0, 0), K(1, 1), K(0, 2), K(1, 2),
                                                              width, height);
  if (!implausible.empty()) reject(std::string(matrix) + ": " + implausible);
  try {
    return kct::PinholeCamera::from_matrix(K, width, height, std::move(distortion), model);
  } catch (const std::invalid_argument& e) {
    reject(std::string(matrix) + " is not a valid camera: " + e.what());
  }
}

bool same_camera(const sensor_msgs::CameraInfo& a, const sensor_msgs::CameraInfo& b) {
  return a.width == b.width && a.height == b.height && a.binning_x == b.binning_x &&
         a.binning_y == b.binning_y && a.roi.x_offset == b.roi.x_offset &&
         a.roi.y_offset == b.roi.y_offset && a.roi.width == b.roi.width &&
         a.roi.height == b.roi.height && a.K == b.K && a.D == b.D && a.P == b.P &&
         a.distortion_model == b.distortion_model;
}

cv::Mat image_for_tracker(const sensor_msgs::Image& msg) {
  const std::string& encoding = msg.encoding;
  const std::string shown = kct::truncate_for_message(encoding);
  const bool bgr = encoding == enc::BGR8 || encoding == enc::RGB8 || encoding == enc::BGRA8 ||
                   encoding == enc::RGBA8 || enc::isBayer(encoding);
  if (!bgr && encoding != enc::MONO8 && encoding != enc::MONO16)
    throw std::invalid_argument("image encoding '" + shown +
                                "' is not supported (mono8, mono16, bgr8, rgb8, bgra8, rgba8, "
                                "bayer_*8, bayer_*16)");
  // Size bounds are the tracker's (kct::implausible_image_size()), checked by the caller before
  // converting; here only what the conversion needs.
  if (msg.width == 0 || msg.height == 0)
    throw std::invalid_argument("image is empty (" + std::to_string(msg.width) + "x" +
                                std::to_string(msg.height) + ")");
  const std::size_t channels = static_cast<std::size_t>(enc::numChannels(encoding));
  const std::size_t byte_depth = static_cast<std::size_t>(enc::bitDepth(encoding) / 8);
  const std::size_t row_bytes = static_cast<std::size_t>(msg.width) * channels * byte_depth;
  if (msg.step < row_bytes || msg.data.size() < static_cast<std::size_t>(msg.step) * msg.height)
    throw std::invalid_argument("malformed '" + shown + "' image: " +
                                std::to_string(msg.width) + "x" + std::to_string(msg.height) +
                                ", step " + std::to_string(msg.step) + " (at least " +
                                std::to_string(row_bytes) + "), " +
                                std::to_string(msg.data.size()) + " bytes of data (at least " +
                                std::to_string(static_cast<std::size_t>(msg.step) * msg.height) +
                                ")");
  // cv_bridge needs 16-bit rows aligned to 2 bytes (an odd step hit an OpenCV assertion) and
  // mishandles big-endian 16-bit data (it returned two 8-bit channels): such images are
  // repacked here into tightly packed host-order rows first.
  const bool host_big_endian = boost::endian::order::native == boost::endian::order::big;
  const bool swap = byte_depth == 2 && static_cast<bool>(msg.is_bigendian) != host_big_endian;
  const sensor_msgs::Image* input = &msg;
  sensor_msgs::Image repacked;
  if (byte_depth == 2 && (swap || msg.step % 2 != 0)) {
    repacked.header = msg.header;
    repacked.width = msg.width;
    repacked.height = msg.height;
    repacked.encoding = msg.encoding;
    repacked.is_bigendian = host_big_endian;
    repacked.step = static_cast<std::uint32_t>(row_bytes);
    repacked.data.resize(row_bytes * msg.height);
    for (std::uint32_t r = 0; r < msg.height; ++r) {
      const std::uint8_t* from = &msg.data[static_cast<std::size_t>(r) * msg.step];
      std::uint8_t* to = &repacked.data[r * row_bytes];
      for (std::size_t i = 0; i < row_bytes; i += 2) {
        to[i] = from[swap ? i + 1 : i];
        to[i + 1] = from[swap ? i : i + 1];
      }
    }
    input = &repacked;
  }
  try {
    if (encoding == enc::MONO16) {
      cv::Mat mono8;
      cv_bridge::toCvCopy(*input)->image.convertTo(mono8, CV_8U, 1.0 / 256.0);
      return mono8;
    }
    return cv_bridge::toCvCopy(*input, bgr ? enc::BGR8 : enc::MONO8)->image;
  } catch (const cv_bridge::Exception& e) {
    throw std::invalid_argument("cannot convert image encoding '" + shown +
                                "': " + kct::truncate_for_message(e.what(), 256));
  } catch (const cv::Exception& e) {
    throw std::invalid_argument("cannot convert image encoding '" + shown +
                                "': " + kct::truncate_for_message(e.what(), 256));
  }
}

cv::Mat image_for_tracker(const sensor_msgs::ImageConstPtr& msg) {
  if (!msg) throw std::invalid_argument("null image message");
  return image_for_tracker(*msg);
}

}  // namespace klt_contour_tracker
