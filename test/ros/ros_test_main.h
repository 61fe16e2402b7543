#pragma once
// main() of every rostest gtest node: gtest, a node with a 2-thread spinner (callbacks run
// while a test waits), and ros::shutdown() after the tests (ROS_ON_DEBIAN.md: avoids the
// teardown abort).
#include <gtest/gtest.h>
#include <ros/ros.h>

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
