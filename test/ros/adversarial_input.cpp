// Issue 8, "never die, never wedge": a klt_only TrackerNodelet in /manager gets the messages
// the outside attack found harmful, each followed by valid frames. Asserted: the manager lives
// (its services answer), every image gets its ~status (with the reason named, values
// truncated), and valid frames afterwards are tracked again with their pose published.
#include <nodelet/NodeletList.h>

#include <opencv2/imgproc.hpp>

#include "tracker_harness.h"

namespace kct_test {
namespace {

using klt_contour_tracker::TrackerStatus;

struct Shared {
  Scene scene;
  kct::Pose truth = crate_pose();
  std::unique_ptr<Harness> harness;
  int seed = 0;
  int images_sent = 0;

  Shared() {
    std::map<std::string, XmlRpc::XmlRpcValue> params{
        {"mesh_resource", XmlRpc::XmlRpcValue("file://" + kMeshPath)},
        {"preset", XmlRpc::XmlRpcValue("klt_only")}};
    set_initial_pose(params, truth);
    harness = std::make_unique<Harness>("adversarial", params);
  }

  sensor_msgs::ImagePtr frame(const ros::Time& stamp) {
    return image_msg(scene.render({truth}, ++seed), stamp);
  }
  TrackerStatus::ConstPtr send(const sensor_msgs::ImagePtr& image,
                               const sensor_msgs::CameraInfo& info) {
    ++images_sent;
    return harness->send(image, info, 60.0);
  }
  /// A valid frame with the crate moved by a small step.
  TrackerStatus::ConstPtr step() {
    truth = kct::test::move(truth, 0.3, {0.1, 1.0, 0.0}, {0.0005, 0.0, 0.0});
    const ros::Time stamp = next_stamp();
    return send(frame(stamp), scene.info(stamp));
  }
};

Shared& shared() {
  static Shared s;
  return s;
}

bool manager_alive() {
  nodelet::NodeletList list;
  return ros::service::call("/manager/list", list);
}

/// Within a few valid frames the crate is tracked again and its pose published.
void expect_tracked_again(const std::string& after) {
  bool tracked = false;
  for (int i = 0; i < 5 && !tracked; ++i) {
    const auto status = shared().step();
    ASSERT_TRUE(status) << "no status after " << after;
    tracked = status->pose_published && status->tracking_state == "tracking" &&
              (status->state == "keypoints" || status->state == "initialized");
  }
  EXPECT_TRUE(tracked) << "not tracked again after " << after;
  const auto pose = shared().harness->last_pose();
  ASSERT_TRUE(pose);
  EXPECT_LT(kct::translation_error(from_pose_msg(pose->pose), shared().truth), 0.01) << after;
  EXPECT_TRUE(manager_alive()) << after;
}

void expect_skipped(const TrackerStatus::ConstPtr& status, const std::string& part) {
  ASSERT_TRUE(status) << "no status for the frame that should say '" << part << "'";
  EXPECT_EQ(status->state, "invalid_input");
  EXPECT_FALSE(status->pose_published);
  EXPECT_NE(status->message.find(part), std::string::npos) << status->message;
}

TEST(AdversarialInput, ValidFramesAreTrackedFirst) {
  ASSERT_TRUE(shared().harness->ready());
  expect_tracked_again("start");
}

// Finding 1: the latency computation threw "Duration is out of dual 32-bit range" after the
// status went out and the manager aborted.
TEST(AdversarialInput, FarFutureAndZeroStampsDoNotKillTheManager) {
  Shared& s = shared();
  for (const ros::Time stamp : {ros::Time(4294967295u, 999999999u), ros::Time(0, 1)}) {
    const auto status = s.send(s.frame(stamp), s.scene.info(stamp));
    ASSERT_TRUE(status) << stamp;
    EXPECT_EQ(status->header.stamp, stamp);
    // Past 2100 the frame is skipped: tf listeners (the nodelet's own one too) overflow ROS
    // time when they add their cache time to such a stamp.
    if (stamp.sec > 4102444800u) {
      EXPECT_NE(status->message.find("after 2100-01-01"), std::string::npos) << status->message;
    }
    ros::WallDuration(0.3).sleep();  // the abort came after the status
    ASSERT_TRUE(manager_alive()) << "manager died after the frame stamped " << stamp;
  }
  expect_tracked_again("far-future and zero stamps");
}

// Finding 2: one camera_info stamped in the future, alone, stopped every later frame.
TEST(AdversarialInput, ALoneFutureCameraInfoDoesNotBlockLaterFrames) {
  Shared& s = shared();
  for (const double ahead_s : {2.0, 1e6}) {
    const ros::Time future(next_stamp().toSec() + ahead_s);
    s.harness->publish_info(s.scene.info(future));
    ros::WallDuration(0.2).sleep();
    for (int i = 0; i < 10; ++i) ASSERT_TRUE(s.step()) << "frame " << i << " after +" << ahead_s;
  }
  // An image whose camera_info never comes is still processed (with the latest one).
  s.harness->publish_image(s.frame(next_stamp()));
  ++s.images_sent;
  expect_tracked_again("a lone future camera_info");
}

// Findings 3 and 4: fx = 1e-3 then fx = 1e7 took 19 s in the energy; both are now rejected as
// implausible before they reach the tracker, and so are a far principal point and NaN.
TEST(AdversarialInput, FocalJumpAndAbsurdIntrinsicsAreRejectedByName) {
  Shared& s = shared();
  const struct {
    int index;
    double value;
    const char* part;
  } cases[] = {{0, 1e-3, "fx = 0.001"}, {0, 1e7, "fx = 1e+07"}, {4, 1e-300, "fy = 1e-300"},
               {2, 1e12, "cx = 1e+12"}};
  for (const auto& c : cases) {
    const ros::Time stamp = next_stamp();
    sensor_msgs::CameraInfo info = s.scene.info(stamp);
    info.K[c.index] = c.value;
    info.P[c.index < 3 ? c.index : c.index + 1] = c.value;
    expect_skipped(s.send(s.frame(stamp), info), c.part);
  }
  expect_tracked_again("implausible intrinsics");
}

// Finding 3: a huge frame is refused before it is converted (bounded memory and time).
TEST(AdversarialInput, HugeFramesAreRefusedBeforeConversion) {
  Shared& s = shared();
  ros::Time stamp;
  sensor_msgs::CameraInfo info;
  for (const auto& [side, part] : std::vector<std::pair<uint32_t, std::string>>{
           {20000, "image size 20000x20000 px: each side must be in [32, 16384]"},
           {16000, "max_image_pixels"}}) {
    stamp = next_stamp();
    info = s.scene.info(stamp);
    info.width = info.height = side;
    auto huge = s.frame(stamp);
    huge->width = huge->height = side;  // the header claims 256-400 Mpx; the data is 640x480
    expect_skipped(s.send(huge, info), part);
  }
  // A real 4000x3000 frame (12 Mpx > the default 8.3 Mpx bound).
  stamp = next_stamp();
  info = s.scene.info(stamp);
  info.width = 4000;
  info.height = 3000;
  info.K[2] = info.P[2] = 2000;
  info.K[5] = info.P[6] = 1500;
  expect_skipped(s.send(image_msg(cv::Mat(3000, 4000, CV_8UC3, cv::Scalar(90, 90, 90)), stamp), info),
                 "max_image_pixels");
  expect_tracked_again("huge frames");
}

// Finding 6: tiny frames are named with the allowed size; a 2^32-1 size stays unsigned.
TEST(AdversarialInput, TinyFramesAndAbsurdSizesAreNamed) {
  Shared& s = shared();
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{1, 1}, {2, 2}, {100000, 1}}) {
    const ros::Time stamp = next_stamp();
    sensor_msgs::CameraInfo info = s.scene.info(stamp);
    info.width = w;
    info.height = h;
    info.K[2] = info.P[2] = w / 2.0;
    info.K[5] = info.P[6] = h / 2.0;
    expect_skipped(s.send(image_msg(cv::Mat(h, w, CV_8UC3, cv::Scalar(90, 90, 90)), stamp), info),
                   std::to_string(w) + "x" + std::to_string(h) + " px: each side must be in [32, 16384]");
  }
  const ros::Time stamp = next_stamp();
  sensor_msgs::CameraInfo info = s.scene.info(stamp);
  info.width = info.height = 4294967295u;
  expect_skipped(s.send(s.frame(stamp), info), "camera_info: image size 4294967295x4294967295 px");
  expect_tracked_again("tiny frames");
}

// Finding 6: bad encodings get a clear message; mono16 with an odd step and big-endian mono16
// are converted and tracked.
TEST(AdversarialInput, EncodingsAreConvertedOrNamedTruncated) {
  Shared& s = shared();
  ros::Time stamp = next_stamp();
  auto image = s.frame(stamp);
  image->encoding = std::string(10000, 'x');
  const auto status = s.send(image, s.scene.info(stamp));
  expect_skipped(status, std::string(64, 'x') + "...");
  EXPECT_LT(status->message.size(), 400u);

  for (const bool big_endian : {false, true}) {
    s.truth = kct::test::move(s.truth, 0.3, {0.1, 1.0, 0.0}, {0.0005, 0.0, 0.0});
    stamp = next_stamp();
    cv::Mat gray;
    cv::cvtColor(s.scene.render({s.truth}, ++s.seed), gray, cv::COLOR_BGR2GRAY);
    auto mono16 = boost::make_shared<sensor_msgs::Image>();
    mono16->header.stamp = stamp;
    mono16->header.frame_id = kCameraFrame;
    mono16->width = gray.cols;
    mono16->height = gray.rows;
    mono16->encoding = "mono16";
    mono16->is_bigendian = big_endian;
    mono16->step = gray.cols * 2 + 1;  // odd: one byte of padding per row
    mono16->data.assign(static_cast<size_t>(mono16->step) * gray.rows, 0);
    for (int r = 0; r < gray.rows; ++r)
      for (int c = 0; c < gray.cols; ++c) {
        const uint16_t v = static_cast<uint16_t>(gray.at<uint8_t>(r, c) * 256);
        uint8_t* p = &mono16->data[r * mono16->step + 2 * c];
        p[big_endian ? 0 : 1] = static_cast<uint8_t>(v >> 8);
        p[big_endian ? 1 : 0] = static_cast<uint8_t>(v & 0xff);
      }
    const auto tracked = s.send(mono16, s.scene.info(stamp));
    ASSERT_TRUE(tracked);
    EXPECT_NE(tracked->state, "invalid_input") << (big_endian ? "big" : "little") << "-endian mono16: "
                                              << tracked->message;
  }
  expect_tracked_again("bad encodings");
}

// Every image sent got exactly one ~status; the manager still runs.
TEST(AdversarialInput, EveryImageGotAStatus) {
  Shared& s = shared();
  ASSERT_TRUE(wait_for([&] { return static_cast<int>(s.harness->statuses().size()) >= s.images_sent; }, 10.0));
  EXPECT_EQ(static_cast<int>(s.harness->statuses().size()), s.images_sent);
  EXPECT_TRUE(manager_alive());
}

}  // namespace
}  // namespace kct_test

KCT_ROSTEST_MAIN("adversarial_input_test")
