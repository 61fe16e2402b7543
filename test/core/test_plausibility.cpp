// Plausibility of outside input (issue 8, findings 3, 4, 6): cameras, poses, image sizes and
// mesh sizes that are finite but absurd are rejected with a message naming the field, the value
// and the allowed range, by the checks and by the Tracker that applies them.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "klt_contour_tracker/core/plausibility.h"
#include "klt_contour_tracker/core/tracker.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(Plausibility, ImageSizesOutsideTheBoundsAreNamed) {
  EXPECT_EQ(implausible_image_size(640, 480, 3840 * 2160), "");
  EXPECT_EQ(implausible_image_size(32, 32, 0), "");
  for (const auto& [w, h] : std::vector<std::pair<std::uint64_t, std::uint64_t>>{
           {1, 1}, {2, 2}, {100000, 1}, {31, 480}, {640, 16385}, {4294967295u, 4294967295u}}) {
    const std::string error = implausible_image_size(w, h, 0);
    EXPECT_TRUE(contains(error, std::to_string(w) + "x" + std::to_string(h)) &&
                contains(error, "[32, 16384]"))
        << w << "x" << h << ": " << error;
  }
  // 2^32 - 1 stays unsigned in the message (it was "-1x-1").
  EXPECT_FALSE(contains(implausible_image_size(4294967295u, 480, 0), "-1"));
  const std::string big = implausible_image_size(4000, 3000, 3840 * 2160);
  EXPECT_TRUE(contains(big, "max_image_pixels") && contains(big, "12000000")) << big;
}

TEST(Plausibility, IntrinsicsAgainstTheImageSize) {
  EXPECT_EQ(implausible_intrinsics(525, 525, 319.5, 239.5, 640, 480), "");
  // Limits: f in [0.05, 50] x 640 = [32, 32000] px; cx in [-640, 1280], cy in [-480, 960].
  EXPECT_EQ(implausible_intrinsics(32, 32, -640, 960, 640, 480), "");
  EXPECT_EQ(implausible_intrinsics(32000, 32000, 1280, -480, 640, 480), "");
  const struct {
    double fx, fy, cx, cy;
    const char* field;
  } bad[] = {{1e-300, 525, 320, 240, "fx = 1e-300"}, {1e300, 525, 320, 240, "fx = 1e+300"},
             {1e-3, 525, 320, 240, "fx = 0.001"},   {1e7, 525, 320, 240, "fx = 1e+07"},
             {525, 31, 320, 240, "fy = 31"},         {525, 525, 1e12, 240, "cx = 1e+12"},
             {525, 525, 320, -481, "cy = -481"},     {std::nan(""), 525, 320, 240, "fx = nan"}};
  for (const auto& b : bad) {
    const std::string error = implausible_intrinsics(b.fx, b.fy, b.cx, b.cy, 640, 480);
    EXPECT_TRUE(contains(error, b.field) && contains(error, "allowed")) << error;
  }
  EXPECT_TRUE(contains(implausible_intrinsics(525, 525, 0, 0, 1, 1), "1x1"));
}

TEST(Plausibility, TrackerRejectsImplausibleCamerasAndMeshSizes) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  const TrackerParams params = make_preset("klt_only");
  EXPECT_THROW(Tracker(mesh, PinholeCamera(1e-3, 1e-3, 320, 240, 640, 480), params),
               std::invalid_argument);
  EXPECT_THROW(Tracker(mesh, PinholeCamera(500, 500, 0.5, 0.5, 1, 1), params),
               std::invalid_argument);
  Tracker tracker(mesh, test::make_camera(), params);
  EXPECT_THROW(tracker.set_camera(PinholeCamera(1e7, 1e7, 320, 240, 640, 480)),
               std::invalid_argument);
  EXPECT_DOUBLE_EQ(tracker.camera().fx(), test::make_camera().fx());  // unchanged
  for (double size : {1e-6, 2e4}) {
    auto scaled = std::make_shared<Mesh>(test::make_box(size, size, size));
    try {
      Tracker t(scaled, test::make_camera(), params);
      ADD_FAILURE() << "no exception for a " << size << " m box";
    } catch (const std::invalid_argument& e) {
      EXPECT_TRUE(contains(e.what(), "mesh_scale")) << e.what();
    }
  }
}

TEST(Plausibility, PosesAgainstTheObjectAndTheCamera) {
  const PinholeCamera camera = test::make_camera();  // fx 600, 640x480
  const Eigen::Vector3d center = Eigen::Vector3d::Zero();
  const double d = 0.2;
  EXPECT_EQ(implausible_pose(test::make_pose(0.4), d, center, camera), "");
  // Depth limits: [0.5 d, fx d / 1 px] = [0.1, 120] m.
  auto at = [](double x, double y, double z) {
    Pose p = Pose::Identity();
    p.translation() = Eigen::Vector3d(x, y, z);
    return p;
  };
  EXPECT_EQ(implausible_pose(at(0, 0, 0.1), d, center, camera), "");
  EXPECT_EQ(implausible_pose(at(0, 0, 120), d, center, camera), "");
  EXPECT_TRUE(contains(implausible_pose(at(0, 0, 1e-9), d, center, camera), "depth z = 1e-09"));
  EXPECT_TRUE(contains(implausible_pose(at(0, 0, 1e300), d, center, camera), "depth z = 1e+300"));
  EXPECT_TRUE(contains(implausible_pose(at(0, 0, 121), d, center, camera), "[0.1, 120] m"));
  EXPECT_TRUE(contains(implausible_pose(at(1e300, 0, 1), d, center, camera), "projects to"));
  EXPECT_TRUE(contains(implausible_pose(at(0, 5, 1), d, center, camera), "projects to"));
  // The bounding-box centre counts, not the object frame's origin.
  EXPECT_TRUE(contains(implausible_pose(at(0, 0, 0.4), d, Eigen::Vector3d(0, 0, -0.35), camera),
                       "depth z = 0.05"));
  EXPECT_TRUE(contains(
      implausible_pose(at(std::numeric_limits<double>::infinity(), 0, 1), d, center, camera),
      "not finite"));
}

TEST(Plausibility, TrackerInitializeRejectsImplausiblePoses) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Tracker tracker(mesh, test::make_camera(), make_preset("klt_only"));
  for (const Eigen::Vector3d& t : {Eigen::Vector3d(0, 0, 1e-9), Eigen::Vector3d(0, 0, 1e300),
                                   Eigen::Vector3d(1e300, 0, 0.5)}) {
    Pose pose = test::make_pose(0.4);
    pose.translation() = t;
    try {
      tracker.initialize(pose);
      ADD_FAILURE() << "no exception for t = " << t.transpose();
    } catch (const std::invalid_argument& e) {
      EXPECT_TRUE(contains(e.what(), "allowed")) << e.what();
    }
  }
  EXPECT_FALSE(tracker.is_initialized());
  EXPECT_NO_THROW(tracker.initialize(test::make_pose(0.4)));
}

TEST(Plausibility, TrackerSkipsFramesOutsideTheSizeBoundWithAClearMessage) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  TrackerParams params = make_preset("klt_only");
  params.max_image_pixels = 640 * 480;
  Tracker tracker(mesh, test::make_camera(), params);
  tracker.initialize(test::make_pose(0.4));
  params.max_image_pixels = 640 * 479;
  tracker.set_params(params);
  const TrackResult result = tracker.track({cv::Mat(480, 640, CV_8UC1, cv::Scalar(90)), 0.0});
  EXPECT_EQ(result.status, TrackStatus::kInvalidInput);
  EXPECT_TRUE(contains(result.message, "max_image_pixels")) << result.message;
  const TrackResult wrong_type = tracker.track({cv::Mat(480, 640, CV_16UC1), 0.0});
  EXPECT_TRUE(contains(wrong_type.message, "CV_16UC1")) << wrong_type.message;
  params.max_image_pixels = 640 * 480;
  tracker.set_params(params);
  EXPECT_EQ(tracker.track({cv::Mat(480, 640, CV_8UC1, cv::Scalar(90)), 0.0}).status,
            TrackStatus::kInitialized);
}

TEST(Plausibility, MessagesTruncateLongValues) {
  EXPECT_EQ(truncate_for_message("mono8"), "mono8");
  const std::string long_text(10000, 'x');
  EXPECT_EQ(truncate_for_message(long_text), std::string(64, 'x') + "...");
  EXPECT_EQ(format_number(1e-300), "1e-300");
}

}  // namespace
}  // namespace kct
