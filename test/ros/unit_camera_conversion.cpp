// camera_from_info / same_camera / image_for_tracker: CameraInfo -> kct::PinholeCamera for
// rectified and raw input (each distortion model), binning and ROI, invalid messages; image
// encodings. ROS libraries, no master.
#include <gtest/gtest.h>
#include <sensor_msgs/distortion_models.h>
#include <sensor_msgs/image_encodings.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "klt_contour_tracker/ros/camera_conversion.h"

namespace {

using klt_contour_tracker::camera_from_info;
using klt_contour_tracker::image_for_tracker;
namespace dm = sensor_msgs::distortion_models;
namespace enc = sensor_msgs::image_encodings;

// 640x480 camera: raw K (fx 500, fy 505, cx 321, cy 239) and a different rectified P (fx 480,
// fy 482, cx 318, cy 241), so each test can tell which one was used.
sensor_msgs::CameraInfo make_info(const std::string& model, std::vector<double> d) {
  sensor_msgs::CameraInfo info;
  info.width = 640;
  info.height = 480;
  info.distortion_model = model;
  info.D = std::move(d);
  info.K = {500, 0, 321, 0, 505, 239, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.P = {480, 0, 318, 0, 0, 482, 241, 0, 0, 0, 1, 0};
  return info;
}

sensor_msgs::CameraInfo plumb_bob() { return make_info(dm::PLUMB_BOB, {-0.2, 0.05, 0.001, 0.002, 0.01}); }

void expect_intrinsics(const kct::PinholeCamera& c, double fx, double fy, double cx, double cy,
                       int width, int height) {
  EXPECT_DOUBLE_EQ(c.fx(), fx);
  EXPECT_DOUBLE_EQ(c.fy(), fy);
  EXPECT_DOUBLE_EQ(c.cx(), cx);
  EXPECT_DOUBLE_EQ(c.cy(), cy);
  EXPECT_EQ(c.width(), width);
  EXPECT_EQ(c.height(), height);
}

// Expects std::invalid_argument whose message contains `part`.
template <typename F>
void expect_rejected(F&& f, const std::string& part) {
  try {
    f();
    ADD_FAILURE() << "no exception; expected one mentioning '" << part << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(CameraFromInfo, RectifiedInputUsesPWithoutDistortion) {
  const kct::PinholeCamera c = camera_from_info(plumb_bob(), true);
  expect_intrinsics(c, 480, 482, 318, 241, 640, 480);
  EXPECT_FALSE(c.has_distortion());
}

TEST(CameraFromInfo, RectifiedInputIgnoresStereoBaseline) {
  sensor_msgs::CameraInfo info = plumb_bob();
  info.P[3] = -480 * 0.12;  // right camera of a stereo pair: Tx = -fx * baseline
  expect_intrinsics(camera_from_info(info, true), 480, 482, 318, 241, 640, 480);
}

TEST(CameraFromInfo, PlumbBobRawInputUsesKAndD) {
  const sensor_msgs::CameraInfo info = plumb_bob();
  const kct::PinholeCamera c = camera_from_info(info, false);
  expect_intrinsics(c, 500, 505, 321, 239, 640, 480);
  EXPECT_EQ(c.distortion_model(), kct::DistortionModel::kRadialTangential);
  EXPECT_EQ(c.distortion(), info.D);
}

TEST(CameraFromInfo, RationalPolynomialKeepsEightCoefficients) {
  const sensor_msgs::CameraInfo info =
      make_info(dm::RATIONAL_POLYNOMIAL, {0.3, -0.1, 0.001, 0.0, 0.02, 0.6, -0.05, 0.01});
  const kct::PinholeCamera c = camera_from_info(info, false);
  EXPECT_EQ(c.distortion_model(), kct::DistortionModel::kRadialTangential);
  EXPECT_EQ(c.distortion(), info.D);
}

TEST(CameraFromInfo, EquidistantBecomesFisheye) {
  const sensor_msgs::CameraInfo info = make_info(dm::EQUIDISTANT, {-0.01, 0.02, -0.01, 0.002});
  const kct::PinholeCamera c = camera_from_info(info, false);
  expect_intrinsics(c, 500, 505, 321, 239, 640, 480);
  EXPECT_EQ(c.distortion_model(), kct::DistortionModel::kEquidistant);
  EXPECT_EQ(c.distortion(), info.D);
}

TEST(CameraFromInfo, ZeroDistortionOfAnyModelIsNoDistortion) {
  for (const char* model : {"plumb_bob", "equidistant", "", "some_model"}) {
    const kct::PinholeCamera c = camera_from_info(make_info(model, {0, 0, 0, 0, 0}), false);
    EXPECT_FALSE(c.has_distortion()) << model;
    expect_intrinsics(c, 500, 505, 321, 239, 640, 480);
  }
  EXPECT_FALSE(camera_from_info(make_info(dm::PLUMB_BOB, {}), false).has_distortion());
}

TEST(CameraFromInfo, UnknownDistortionModelRejected) {
  const auto info = make_info("kannala_brandt_7", {0.1, 0.0, 0.0, 0.0});
  expect_rejected([&] { camera_from_info(info, false); }, "'kannala_brandt_7'");
  // Rectified input does not use D: the model does not matter.
  EXPECT_NO_THROW(camera_from_info(info, true));
}

TEST(CameraFromInfo, WrongCoefficientCountsRejected) {
  expect_rejected([] { camera_from_info(make_info(dm::PLUMB_BOB, {0.1, 0.2, 0.0}), false); },
                  "3 coefficients");
  expect_rejected(
      [] { camera_from_info(make_info(dm::EQUIDISTANT, {0.1, 0.2, 0.0, 0.0, 0.0}), false); },
      "needs 4 coefficients");
}

TEST(CameraFromInfo, UncalibratedRejected) {
  sensor_msgs::CameraInfo info = plumb_bob();
  info.K.fill(0.0);
  info.P.fill(0.0);
  expect_rejected([&] { camera_from_info(info, true); }, "not calibrated");
  expect_rejected([&] { camera_from_info(info, false); }, "not calibrated");
  // K set but no P: rectified input cannot be used, raw input can.
  info = plumb_bob();
  info.P.fill(0.0);
  expect_rejected([&] { camera_from_info(info, true); }, "~input_is_rectified");
  EXPECT_NO_THROW(camera_from_info(info, false));
}

TEST(CameraFromInfo, InvalidValuesRejected) {
  sensor_msgs::CameraInfo info = plumb_bob();
  info.K[0] = std::numeric_limits<double>::quiet_NaN();
  expect_rejected([&] { camera_from_info(info, false); }, "K has a non-finite entry");
  info = plumb_bob();
  info.D[1] = std::numeric_limits<double>::infinity();
  expect_rejected([&] { camera_from_info(info, false); }, "D has a non-finite entry");
  info = plumb_bob();
  info.width = 0;
  expect_rejected([&] { camera_from_info(info, true); }, "image size 0x480 px");
  info = plumb_bob();
  info.P[5] = -482;
  expect_rejected([&] { camera_from_info(info, true); }, "P: fy = -482");
  info = plumb_bob();
  info.K[1] = 0.5;  // skew
  expect_rejected([&] { camera_from_info(info, false); }, "not a pinhole matrix");
}

// Binning and ROI (image_geometry's reduced camera): a point seen at full-resolution pixel u
// is at (u - roi_offset) / binning in the reduced image, and the camera is the reduced size.
TEST(CameraFromInfo, BinningScalesTheCamera) {
  sensor_msgs::CameraInfo info = plumb_bob();
  info.binning_x = 2;
  info.binning_y = 4;
  expect_intrinsics(camera_from_info(info, true), 240, 120.5, 159, 60.25, 320, 120);
  const kct::PinholeCamera raw = camera_from_info(info, false);
  expect_intrinsics(raw, 250, 126.25, 160.5, 59.75, 320, 120);
  EXPECT_EQ(raw.distortion(), info.D);  // distortion acts on normalized coordinates
}

TEST(CameraFromInfo, RoiShiftsThePrincipalPoint) {
  sensor_msgs::CameraInfo info = plumb_bob();
  info.roi.x_offset = 100;
  info.roi.y_offset = 50;
  info.roi.width = 320;
  info.roi.height = 200;
  expect_intrinsics(camera_from_info(info, false), 500, 505, 221, 189, 320, 200);
  info.binning_x = info.binning_y = 2;
  expect_intrinsics(camera_from_info(info, false), 250, 252.5, 110.5, 94.5, 160, 100);
}

TEST(CameraFromInfo, RoiOutsideTheImageRejected) {
  sensor_msgs::CameraInfo info = plumb_bob();
  info.roi.x_offset = 400;
  info.roi.width = 320;
  info.roi.height = 100;
  expect_rejected([&] { camera_from_info(info, false); }, "outside");
}

TEST(SameCamera, ComparesCalibrationNotHeader) {
  const sensor_msgs::CameraInfo a = plumb_bob();
  sensor_msgs::CameraInfo b = a;
  b.header.stamp = ros::Time(12.5);
  b.header.frame_id = "other";
  EXPECT_TRUE(klt_contour_tracker::same_camera(a, b));
  b.P[0] = 481;
  EXPECT_FALSE(klt_contour_tracker::same_camera(a, b));
  b = a;
  b.roi.x_offset = 2;
  EXPECT_FALSE(klt_contour_tracker::same_camera(a, b));
  b = a;
  b.binning_x = 2;
  EXPECT_FALSE(klt_contour_tracker::same_camera(a, b));
  b = a;
  b.distortion_model = dm::EQUIDISTANT;
  EXPECT_FALSE(klt_contour_tracker::same_camera(a, b));
}

// 2x2 image of the given encoding filled with the bytes of `pixel`, repeated.
sensor_msgs::Image make_image(const std::string& encoding, const std::vector<uint8_t>& pixel) {
  sensor_msgs::Image image;
  image.encoding = encoding;
  image.width = 2;
  image.height = 2;
  image.step = static_cast<uint32_t>(2 * pixel.size());
  for (int i = 0; i < 4; ++i) image.data.insert(image.data.end(), pixel.begin(), pixel.end());
  return image;
}

TEST(ImageForTracker, GreyEncodings) {
  const sensor_msgs::Image mono8 = make_image(enc::MONO8, {77});
  const cv::Mat a = image_for_tracker(mono8);
  ASSERT_EQ(a.type(), CV_8UC1);
  EXPECT_EQ(a.at<uint8_t>(1, 1), 77);
  EXPECT_NE(static_cast<const void*>(a.data), static_cast<const void*>(mono8.data.data()));

  sensor_msgs::Image mono16 = make_image(enc::MONO16, {0, 0});
  const uint16_t value = 0x1234;
  for (int i = 0; i < 4; ++i) std::memcpy(&mono16.data[2 * i], &value, 2);  // host byte order
  const cv::Mat b = image_for_tracker(mono16);
  ASSERT_EQ(b.type(), CV_8UC1);
  EXPECT_EQ(b.at<uint8_t>(0, 1), 0x12);
}

TEST(ImageForTracker, ColourEncodingsBecomeBgr) {
  const cv::Vec3b bgr(30, 20, 10);
  const std::vector<std::pair<std::string, std::vector<uint8_t>>> cases = {
      {enc::BGR8, {30, 20, 10}},
      {enc::RGB8, {10, 20, 30}},
      {enc::BGRA8, {30, 20, 10, 255}},
      {enc::RGBA8, {10, 20, 30, 255}}};
  for (const auto& [encoding, pixel] : cases) {
    const cv::Mat image = image_for_tracker(make_image(encoding, pixel));
    ASSERT_EQ(image.type(), CV_8UC3) << encoding;
    EXPECT_EQ(image.at<cv::Vec3b>(1, 0), bgr) << encoding;
  }
  const cv::Mat bayer = image_for_tracker(make_image(enc::BAYER_RGGB8, {100}));
  EXPECT_EQ(bayer.type(), CV_8UC3);
  EXPECT_EQ(bayer.size(), cv::Size(2, 2));
}

TEST(ImageForTracker, OtherEncodingsRejectedByName) {
  for (const char* encoding : {"32FC1", "16UC1", "yuv422", "8UC3", "bgr16"})
    expect_rejected([&] { image_for_tracker(make_image(encoding, {0, 0, 0, 0, 0, 0})); },
                    std::string("'") + encoding + "'");
}

TEST(ImageForTracker, MalformedImagesRejected) {
  sensor_msgs::Image image = make_image(enc::BGR8, {1, 2, 3});
  image.data.resize(5);
  expect_rejected([&] { image_for_tracker(image); }, "malformed 'bgr8'");
  image = make_image(enc::BGR8, {1, 2, 3});
  image.step = 4;  // < 2 pixels x 3 bytes
  expect_rejected([&] { image_for_tracker(image); }, "step 4");
  image.width = 0;
  expect_rejected([&] { image_for_tracker(image); }, "empty");
  expect_rejected([] { image_for_tracker(sensor_msgs::ImageConstPtr()); }, "null");
}

// Issue 8 findings 4 and 6: implausible intrinsics and sizes are named with their value.
TEST(CameraFromInfo, ImplausibleIntrinsicsAndSizesNamed) {
  sensor_msgs::CameraInfo info = plumb_bob();
  info.K[0] = 1e-300;
  expect_rejected([&] { camera_from_info(info, false); }, "fx = 1e-300");
  info = plumb_bob();
  info.K[0] = 1e300;
  expect_rejected([&] { camera_from_info(info, false); }, "fx = 1e+300");
  info = plumb_bob();
  info.K[2] = 1e12;
  expect_rejected([&] { camera_from_info(info, false); }, "cx = 1e+12");
  info = plumb_bob();
  info.P[0] = 1e7;
  expect_rejected([&] { camera_from_info(info, true); }, "P: fx = 1e+07");
  for (const auto& [w, h] : std::vector<std::pair<uint32_t, uint32_t>>{
           {1, 1}, {2, 2}, {100000, 1}, {4294967295u, 4294967295u}}) {
    info = plumb_bob();
    info.width = w;
    info.height = h;
    expect_rejected([&] { camera_from_info(info, false); },
                    "image size " + std::to_string(w) + "x" + std::to_string(h) + " px");
  }
  info = plumb_bob();
  info.binning_x = 64;  // 640 / 64 = 10 px wide
  expect_rejected([&] { camera_from_info(info, false); }, "10x480 px");
}

TEST(ImageForTracker, Mono16WithAnOddStepIsRepacked) {
  sensor_msgs::Image image;
  image.encoding = enc::MONO16;
  image.width = 2;
  image.height = 2;
  image.step = 5;  // 4 bytes of pixels + 1 byte of padding per row
  const uint16_t value = 0xab00;
  image.data.assign(10, 0);
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 2; ++c) std::memcpy(&image.data[r * 5 + 2 * c], &value, 2);
  const cv::Mat out = image_for_tracker(image);
  ASSERT_EQ(out.type(), CV_8UC1);
  EXPECT_EQ(out.at<uint8_t>(1, 1), 0xab);
}

TEST(ImageForTracker, BigEndianMono16IsConverted) {
  sensor_msgs::Image image = make_image(enc::MONO16, {0x12, 0x34});  // big-endian 0x1234
  image.is_bigendian = 1;
  const cv::Mat out = image_for_tracker(image);
  ASSERT_EQ(out.type(), CV_8UC1);
  EXPECT_EQ(out.at<uint8_t>(1, 0), 0x12);
}

TEST(ImageForTracker, LongEncodingsAreTruncatedInMessages) {
  const std::string encoding(10000, 'e');
  try {
    image_for_tracker(make_image(encoding, {0}));
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_LT(std::string(e.what()).size(), 300u);
    EXPECT_NE(std::string(e.what()).find(std::string(64, 'e') + "..."), std::string::npos);
  }
}

}  // namespace
