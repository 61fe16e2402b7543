// rostest: sim time. The generated test bag is played by `rosbag play --clock` (started here,
// paced on ~status) into the nodelet of launch/tracker_nodelet.launch with use_sim_time; every
// output (~pose, ~pose_with_covariance, ~status, ~debug_image, tf, ~marker) carries the stamp of
// an image of the bag, never the wall clock or the sim clock.
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/Marker.h>

#include <cstdlib>
#include <functional>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "klt_contour_tracker/Init.h"
#include "klt_contour_tracker/TrackerStatus.h"

#include "ros_test_util.h"

namespace {

const std::string kNode = "/klt_contour_tracker";

/// Stamps of every output message, by output.
class Stamps {
 public:
  void add(const std::string& output, const ros::Time& stamp) {
    std::lock_guard<std::mutex> lock(mutex_);
    stamps_[output].push_back(stamp);
  }
  std::map<std::string, std::vector<ros::Time>> get() {
    std::lock_guard<std::mutex> lock(mutex_);
    return stamps_;
  }

 private:
  std::mutex mutex_;
  std::map<std::string, std::vector<ros::Time>> stamps_;
};

TEST(SimTime, EveryOutputIsStampedWithItsImageStamp) {
  ASSERT_TRUE(ros::Time::isSimTime()) << "use_sim_time must be set by the .test file";
  const std::string bag_path = KCT_TEST_DATA_DIR "/small.bag";
  std::set<ros::Time> image_stamps;
  geometry_msgs::Pose first_truth;
  bool have_truth = false;
  for (const BagFrame& frame : read_bag(bag_path)) {  // in stamp order
    if (frame.image) image_stamps.insert(frame.image->header.stamp);
    if (frame.ground_truth && !have_truth) {
      first_truth = frame.ground_truth->pose;
      have_truth = true;
    }
  }
  ASSERT_GE(image_stamps.size(), 10u);
  ASSERT_TRUE(have_truth);

  ros::NodeHandle nh;
  Stamps stamps;
  std::vector<ros::Subscriber> subs;
  subs.push_back(nh.subscribe<geometry_msgs::PoseStamped>(
      kNode + "/pose", 100, [&](const auto& m) { stamps.add("pose", m->header.stamp); }));
  subs.push_back(nh.subscribe<geometry_msgs::PoseWithCovarianceStamped>(
      kNode + "/pose_with_covariance", 100,
      [&](const auto& m) { stamps.add("pose_with_covariance", m->header.stamp); }));
  subs.push_back(nh.subscribe<klt_contour_tracker::TrackerStatus>(
      kNode + "/status", 100, [&](const auto& m) { stamps.add("status", m->header.stamp); }));
  subs.push_back(nh.subscribe<sensor_msgs::Image>(
      kNode + "/debug_image", 100, [&](const auto& m) { stamps.add("debug_image", m->header.stamp); }));
  subs.push_back(nh.subscribe<visualization_msgs::Marker>(
      kNode + "/marker", 1, [&](const auto& m) { stamps.add("marker", m->header.stamp); }));
  subs.push_back(nh.subscribe<tf2_msgs::TFMessage>("/tf", 100, [&](const auto& m) {
    for (const auto& t : m->transforms)
      if (t.child_frame_id == "object") stamps.add("tf", t.header.stamp);
  }));

  // The nodelet starts without an initial pose: give it the bag's first ground truth.
  ASSERT_TRUE(ros::service::waitForService(kNode + "/init", 60000));
  klt_contour_tracker::Init init;
  init.request.pose.pose = first_truth;
  ASSERT_TRUE(ros::service::call(kNode + "/init", init));
  ASSERT_TRUE(init.response.accepted) << init.response.message;
  ASSERT_TRUE(wait_for([&] { return subs[3].getNumPublishers() > 0 && subs[2].getNumPublishers() > 0; }, 30.0));

  const std::string command = "rosbag play -q --clock -d 2 --rate-control-topic " + kNode +
                              "/status --rate-control-max-delay 0.2 " + bag_path;
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  ASSERT_TRUE(wait_for([&] { return stamps.get()["status"].size() >= image_stamps.size(); }, 60.0));
  ros::WallDuration(1.0).sleep();

  const auto all = stamps.get();
  for (const std::string output :
       {"pose", "pose_with_covariance", "status", "debug_image", "tf", "marker"}) {
    ASSERT_TRUE(all.count(output)) << "no " << output << " received";
    const std::vector<ros::Time>& got = all.at(output);
    for (const ros::Time& stamp : got)
      EXPECT_TRUE(image_stamps.count(stamp)) << output << " stamped " << stamp << ": not an image stamp";
  }
  // Every image got its status and (the crate is tracked throughout) its pose.
  EXPECT_EQ(all.at("status").size(), image_stamps.size());
  EXPECT_EQ(all.at("pose").size(), image_stamps.size());
  EXPECT_EQ(all.at("pose_with_covariance").size(), image_stamps.size());
  EXPECT_EQ(all.at("marker").front(), *image_stamps.begin());
}

}  // namespace

KCT_ROSTEST_MAIN("sim_time_stamps_test")
