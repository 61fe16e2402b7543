#pragma once
// Shared by the rostest gtest nodes: waiting on a condition, and main().
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <functional>

/// Polls `condition` every 10 ms (wall time) until it holds or `timeout_s` passes; returns it.
inline bool wait_for(const std::function<bool()>& condition, double timeout_s) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout_s);
  while (ros::ok() && ros::WallTime::now() < end) {
    if (condition()) return true;
    ros::WallDuration(0.01).sleep();
  }
  return condition();
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
