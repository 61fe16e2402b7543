// rostest: invalid configurations. Each bad nodelet must be reported (NODELET_FATAL) and make
// no subscription, while the manager and a correctly configured nodelet keep running.
#include <gtest/gtest.h>
#include <nodelet/NodeletList.h>
#include <nodelet/NodeletLoad.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <functional>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "ros_test_util.h"

namespace {

const std::string kMesh = std::string("file://") + KCT_SOURCE_DIR "/models/demo_crate.obj";
const std::string kUrdf =
    "<robot name='crate'><link name='crate'><visual><geometry><mesh filename='" + kMesh +
    "'/></geometry></visual></link></robot>";

/// An .obj file that is not a mesh, written once for the test.
std::string corrupt_mesh_path() {
  const std::string path = "/tmp/kct_bad_config_corrupt_" + std::to_string(::getpid()) + ".obj";
  std::ofstream(path) << "this is not a mesh \x01\x02\n f 1 2 99\n";
  return path;
}

/// Topics someone subscribes to, from the master (getSystemState).
std::set<std::string> subscribed_topics() {
  XmlRpc::XmlRpcValue args, result, payload;
  args[0] = ros::this_node::getName();
  std::set<std::string> topics;
  if (!ros::master::execute("getSystemState", args, result, payload, true)) return topics;
  XmlRpc::XmlRpcValue& subscribers = payload[1];
  for (int i = 0; i < subscribers.size(); ++i)
    topics.insert(static_cast<std::string>(subscribers[i][0]));
  return topics;
}

/// Sets the valid parameters of nodelet `name`, lets `spoil` break one, loads it into /manager
/// with its camera in /<name>_camera. Returns the service's success flag.
bool load(const std::string& name, const std::function<void(ros::NodeHandle&)>& spoil) {
  ros::NodeHandle nh("/" + name);
  nh.setParam("mesh_resource", kMesh);
  nh.setParam("initial_pose/position", std::vector<double>{0.0, 0.0, 0.5});
  nh.setParam("initial_pose/orientation", std::vector<double>{0.0, 0.0, 0.0, 1.0});
  spoil(nh);
  nodelet::NodeletLoad srv;
  srv.request.name = "/" + name;
  srv.request.type = "klt_contour_tracker/TrackerNodelet";
  srv.request.remap_source_args = {"/image", "/camera_info"};
  srv.request.remap_target_args = {"/" + name + "_camera/image_raw",
                                   "/" + name + "_camera/camera_info"};
  return ros::service::call("/manager/load_nodelet", srv) && srv.response.success;
}

TEST(BadConfig, ReportedWithoutSubscriptionAndManagerKeepsRunning) {
  ASSERT_TRUE(ros::service::waitForService("/manager/load_nodelet", 30000));
  const std::vector<std::pair<std::string, std::function<void(ros::NodeHandle&)>>> bad = {
      {"missing_mesh", [](ros::NodeHandle& nh) { nh.setParam("mesh_resource", "/nonexistent/mesh.obj"); }},
      {"no_mesh_param", [](ros::NodeHandle& nh) { nh.deleteParam("mesh_resource"); }},
      {"unknown_preset", [](ros::NodeHandle& nh) { nh.setParam("preset", "no_such_preset"); }},
      {"out_of_range", [](ros::NodeHandle& nh) { nh.setParam("klt_window_px", 4); }},
      {"wrong_type", [](ros::NodeHandle& nh) { nh.setParam("max_keypoints", "many"); }},
      {"behind_camera",
       [](ros::NodeHandle& nh) {
         nh.setParam("initial_pose/position", std::vector<double>{0.0, 0.0, -0.5});
       }},
      {"urdf_without_link",
       [](ros::NodeHandle& nh) {
         nh.setParam("model_description", kUrdf);
         nh.setParam("object_link", "no_such_link");
       }},
      {"urdf_without_object_link", [](ros::NodeHandle& nh) { nh.setParam("model_description", kUrdf); }},
      {"broken_urdf", [](ros::NodeHandle& nh) {
         nh.setParam("model_description", std::string("<robot name='x'><link"));
         nh.setParam("object_link", "crate");
       }},
      {"missing_package",
       [](ros::NodeHandle& nh) {
         nh.setParam("mesh_resource", "package://no_such_package_kct/meshes/x.obj");
       }},
      {"corrupt_mesh", [](ros::NodeHandle& nh) { nh.setParam("mesh_resource", corrupt_mesh_path()); }},
      {"nan_pose",
       [](ros::NodeHandle& nh) {
         nh.setParam("initial_pose/position",
                     std::vector<double>{std::numeric_limits<double>::quiet_NaN(), 0.0, 0.5});
       }},
  };
  for (const auto& [name, spoil] : bad) EXPECT_TRUE(load(name, spoil)) << name;
  // The control: the same parameters unspoiled do subscribe (so the check below can fail).
  ASSERT_TRUE(load("good", [](ros::NodeHandle&) {}));
  ASSERT_TRUE(wait_for([] { return subscribed_topics().count("/good_camera/image_raw") > 0; }, 30.0))
      << "the correctly configured nodelet never subscribed";

  const std::set<std::string> topics = subscribed_topics();
  for (const auto& entry : bad) {
    EXPECT_EQ(topics.count("/" + entry.first + "_camera/image_raw"), 0u) << entry.first;
    EXPECT_EQ(topics.count("/" + entry.first + "_camera/camera_info"), 0u) << entry.first;
  }

  // The manager is alive and still hosts every nodelet.
  nodelet::NodeletList list;
  ASSERT_TRUE(ros::service::call("/manager/list", list));
  for (const auto& entry : bad) {
    EXPECT_NE(std::find(list.response.nodelets.begin(), list.response.nodelets.end(),
                        "/" + entry.first),
              list.response.nodelets.end())
        << entry.first;
  }
}

}  // namespace

KCT_ROSTEST_MAIN("bad_config_test")
