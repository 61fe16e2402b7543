#pragma once
// Shared by the rostest gtest nodes: waiting on a condition, reading the test bag, loading a
// tracker nodelet into the test's manager, and main().
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <nodelet/NodeletLoad.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <functional>
#include <map>
#include <string>
#include <vector>

/// Polls `condition` every 10 ms (wall time) until it holds or `timeout_s` passes; returns it.
inline bool wait_for(const std::function<bool()>& condition, double timeout_s) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout_s);
  while (ros::ok() && ros::WallTime::now() < end) {
    if (condition()) return true;
    ros::WallDuration(0.01).sleep();
  }
  return condition();
}

/// One stamp of a test bag: its image, camera_info and ground-truth pose (null when missing).
struct BagFrame {
  sensor_msgs::Image::ConstPtr image;
  sensor_msgs::CameraInfo::ConstPtr info;
  geometry_msgs::PoseStamped::ConstPtr ground_truth;
};

/// The bag's images, camera_infos and PoseStamped ground truth grouped by stamp, in stamp order.
inline std::vector<BagFrame> read_bag(const std::string& path) {
  std::map<ros::Time, BagFrame> by_stamp;
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (auto image = m.instantiate<sensor_msgs::Image>())
      by_stamp[image->header.stamp].image = image;
    else if (auto info = m.instantiate<sensor_msgs::CameraInfo>())
      by_stamp[info->header.stamp].info = info;
    else if (auto pose = m.instantiate<geometry_msgs::PoseStamped>())
      by_stamp[pose->header.stamp].ground_truth = pose;
  }
  std::vector<BagFrame> frames;
  for (const auto& entry : by_stamp) frames.push_back(entry.second);
  return frames;
}

/// Sets `name`'s ~mesh_resource to the demo crate and ~initial_pose to `initial_pose`
/// (camera frame), as the bag tests track it.
inline void set_demo_crate_params(const std::string& name, const geometry_msgs::Pose& initial_pose) {
  ros::NodeHandle nh;
  nh.setParam(name + "/mesh_resource", std::string("file://") + KCT_SOURCE_DIR "/models/demo_crate.obj");
  const geometry_msgs::Point& p = initial_pose.position;
  const geometry_msgs::Quaternion& q = initial_pose.orientation;
  nh.setParam(name + "/initial_pose/position", std::vector<double>{p.x, p.y, p.z});
  nh.setParam(name + "/initial_pose/orientation", std::vector<double>{q.x, q.y, q.z, q.w});
}

/// Loads a klt_contour_tracker/TrackerNodelet named `name` (e.g. "/tracker", its parameters
/// set before) into the test's manager /manager, with its image and camera_info topics
/// remapped to `camera_ns`/image_raw and `camera_ns`/camera_info. Returns whether it loaded.
inline bool load_tracker_nodelet(const std::string& name, const std::string& camera_ns = "/camera") {
  if (!ros::service::waitForService("/manager/load_nodelet", 30000)) return false;
  nodelet::NodeletLoad load;
  load.request.name = name;
  load.request.type = "klt_contour_tracker/TrackerNodelet";
  load.request.remap_source_args = {"/image", "/camera_info"};
  load.request.remap_target_args = {camera_ns + "/image_raw", camera_ns + "/camera_info"};
  return ros::service::call("/manager/load_nodelet", load) && load.response.success;
}

// main(): gtest, a node with a 2-thread spinner (callbacks run while a test waits), and
// ros::shutdown() after the tests (ROS_ON_DEBIAN.md: avoids the teardown abort).
#define KCT_ROSTEST_MAIN(node_name)              \
  int main(int argc, char** argv) {              \
    testing::InitGoogleTest(&argc, argv);        \
    ros::init(argc, argv, node_name);            \
    ros::AsyncSpinner spinner(2);                \
    spinner.start();                             \
    const int result = RUN_ALL_TESTS();          \
    spinner.stop();                              \
    ros::shutdown();                             \
    return result;                               \
  }
