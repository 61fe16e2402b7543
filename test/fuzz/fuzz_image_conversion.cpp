// libFuzzer target: what the nodelet does with an image + camera_info pair before tracking
// (src/ros/camera_conversion.cpp and the checks in TrackerNodelet::process_image): the size
// bound, camera_from_info() and image_for_tracker(). Input layout (little-endian, zero-filled
// when short; test/fuzz/make_seeds.py writes it):
//   image:  u32 width, u32 height, u32 step, u8 is_bigendian, u8 encoding (index into
//           kEncodings; 255 = u16 length + that many bytes of encoding text)
//   info:   u32 width, u32 height, u32 binning_x, u32 binning_y, u32 roi x, y, w, h,
//           u8 distortion model index, u8 D count (% 16), u8 input_is_rectified,
//           f64 K[9], f64 P[12], f64 D[count]
//   rest:   the image's data bytes
// Only std::invalid_argument may leave the conversion; the converted image must have the
// camera's size and 1 or 3 8-bit channels.
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

#include "klt_contour_tracker/core/plausibility.h"
#include "klt_contour_tracker/core/tracker_params.h"
#include "klt_contour_tracker/ros/camera_conversion.h"

namespace {

class Reader {
 public:
  Reader(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  template <typename T>
  T get() {
    T value{};
    const size_t n = std::min(sizeof(T), size_ - pos_);
    std::memcpy(&value, data_ + pos_, n);
    pos_ += n;
    return value;
  }
  std::string text(size_t length) {
    length = std::min(length, size_ - pos_);
    std::string s(reinterpret_cast<const char*>(data_ + pos_), length);
    pos_ += length;
    return s;
  }
  const uint8_t* rest(size_t& length) const {
    length = size_ - pos_;
    return data_ + pos_;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

const char* const kEncodings[] = {"mono8",        "mono16",       "bgr8",         "rgb8",
                                  "bgra8",        "rgba8",        "bayer_rggb8",  "bayer_bggr16",
                                  "32FC1",        "yuv422",       "16UC1",        "bgr16"};
const char* const kModels[] = {"plumb_bob", "rational_polynomial", "equidistant", ""};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Reader in(data, size);
  sensor_msgs::Image image;
  image.width = in.get<uint32_t>();
  image.height = in.get<uint32_t>();
  image.step = in.get<uint32_t>();
  image.is_bigendian = in.get<uint8_t>();
  const uint8_t encoding = in.get<uint8_t>();
  if (encoding == 255)
    image.encoding = in.text(in.get<uint16_t>());
  else
    image.encoding = kEncodings[encoding % (sizeof(kEncodings) / sizeof(*kEncodings))];
  sensor_msgs::CameraInfo info;
  info.width = in.get<uint32_t>();
  info.height = in.get<uint32_t>();
  info.binning_x = in.get<uint32_t>();
  info.binning_y = in.get<uint32_t>();
  info.roi.x_offset = in.get<uint32_t>();
  info.roi.y_offset = in.get<uint32_t>();
  info.roi.width = in.get<uint32_t>();
  info.roi.height = in.get<uint32_t>();
  info.distortion_model = kModels[in.get<uint8_t>() % 4];
  const int d_count = in.get<uint8_t>() % 16;
  const bool rectified = in.get<uint8_t>() & 1;
  for (double& k : info.K) k = in.get<double>();
  for (double& p : info.P) p = in.get<double>();
  for (int i = 0; i < d_count; ++i) info.D.push_back(in.get<double>());
  size_t data_size = 0;
  const uint8_t* pixels = in.rest(data_size);
  image.data.assign(pixels, pixels + data_size);

  // TrackerNodelet::process_image(): size bound first (nothing is converted beyond it), then
  // the camera, then the size match, then the conversion.
  const kct::TrackerParams params;
  if (!kct::implausible_image_size(image.width, image.height,
                                   static_cast<uint64_t>(params.max_image_pixels))
           .empty())
    return 0;
  kct::PinholeCamera camera;
  try {
    camera = klt_contour_tracker::camera_from_info(info, rectified);
  } catch (const std::invalid_argument&) {
    return 0;
  }
  if (!kct::implausible_camera(camera).empty()) __builtin_trap();  // accepted => plausible
  if (static_cast<int>(image.width) != camera.width() ||
      static_cast<int>(image.height) != camera.height())
    return 0;
  try {
    const cv::Mat frame = klt_contour_tracker::image_for_tracker(image);
    if (frame.cols != camera.width() || frame.rows != camera.height() || frame.depth() != CV_8U ||
        (frame.channels() != 1 && frame.channels() != 3))
      __builtin_trap();
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
