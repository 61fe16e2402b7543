// rostest (issue 10 item 4): the rostests' 40-frame bag (rendered at 30 Hz stamps) played three
// times at ~rate_hz (30 Hz: its real rate) into a TrackerNodelet with the default preset and
// queue. The nodelet is warmed up with the first frame (the tracker and its visibility table are
// built on the first image), then every frame is published at the stated rate without waiting
// for the tracker. Asserted: at least ~min_status_ratio of the images sent got a ~status, and the
// statuses plus the frames the nodelet reports as dropped before it account for every image.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <mutex>
#include <string>
#include <vector>

#include "klt_contour_tracker/TrackerStatus.h"
#include "ros_test_util.h"

namespace {

TEST(CameraRate, EveryImageSentAtTheCameraRateGetsAStatus) {
  ros::NodeHandle nh, private_nh("~");
  const std::string bag_path = private_nh.param<std::string>("bag", KCT_TEST_DATA_DIR "/small.bag");
  const double rate_hz = private_nh.param("rate_hz", 30.0);
  const double min_ratio = private_nh.param("min_status_ratio", 0.99);
  const int loops = private_nh.param("loops", 3);
  const std::vector<BagFrame> frames = read_bag(bag_path);
  ASSERT_GE(frames.size(), 10u);
  for (const BagFrame& f : frames) ASSERT_TRUE(f.image && f.info && f.ground_truth);

  const std::string name = "/rate_tracker";  // default preset and queue: not set here
  set_demo_crate_params(name, frames.front().ground_truth->pose);
  ASSERT_TRUE(load_tracker_nodelet(name));

  std::mutex mutex;
  std::vector<klt_contour_tracker::TrackerStatus::ConstPtr> statuses;
  ros::Subscriber status_sub = nh.subscribe<klt_contour_tracker::TrackerStatus>(
      name + "/status", 1000, [&](const klt_contour_tracker::TrackerStatus::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        statuses.push_back(m);
      });
  auto count = [&] {
    std::lock_guard<std::mutex> lock(mutex);
    return statuses.size();
  };
  ros::Publisher image_pub = nh.advertise<sensor_msgs::Image>("/camera/image_raw", 10);
  ros::Publisher info_pub = nh.advertise<sensor_msgs::CameraInfo>("/camera/camera_info", 10);
  ASSERT_TRUE(wait_for([&] {
    return image_pub.getNumSubscribers() > 0 && info_pub.getNumSubscribers() > 0 &&
           status_sub.getNumPublishers() > 0;
  }, 30.0));

  // Warm-up: the first image builds the tracker.
  info_pub.publish(frames.front().info);
  image_pub.publish(frames.front().image);
  ASSERT_TRUE(wait_for([&] { return count() >= 1; }, 300.0)) << "no status for the first frame";
  const std::size_t before = count();

  // The bag `loops` times at rate_hz (each loop restarts the stamps, as rosbag play -l does).
  int sent = 0;
  ros::WallRate rate(rate_hz);
  for (int loop = 0; loop < loops; ++loop)
    for (std::size_t i = (loop == 0 ? 1 : 0); i < frames.size(); ++i) {
      info_pub.publish(frames[i].info);
      image_pub.publish(frames[i].image);
      ++sent;
      rate.sleep();
    }
  // Wait until the statuses stop coming (2 s without a new one).
  std::size_t last = count();
  while (wait_for([&] { return count() > last; }, 2.0)) last = count();

  std::lock_guard<std::mutex> lock(mutex);
  const std::size_t received = statuses.size() - before;
  const std::uint64_t dropped = statuses.back()->dropped_frames_total;
  std::printf("[camera_rate] %d images sent at %.1f Hz: %zu statuses, %llu reported dropped before "
              "the tracker, median frame time %.1f ms\n",
              sent, rate_hz, received, static_cast<unsigned long long>(dropped),
              statuses[before + received / 2]->frame_time_ms);
  EXPECT_GE(static_cast<double>(received), min_ratio * sent)
      << "frames lost at " << rate_hz << " Hz (the tracker is slower than the camera?)";
  // Every image is accounted for: a status, or counted as dropped before the tracker (the
  // counter may see a drop at a loop boundary as a restart, hence the tolerance of one per loop).
  EXPECT_LE(received + dropped, static_cast<std::size_t>(sent));
  EXPECT_GE(received + dropped + loops, static_cast<std::size_t>(sent));
}

}  // namespace

KCT_ROSTEST_MAIN("camera_rate_test")
