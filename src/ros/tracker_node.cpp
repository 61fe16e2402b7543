// Standalone node: loads the TrackerNodelet in-process under this node's name, so parameters
// (~...) and remappings (image:=..., camera_info:=...) behave exactly as for the nodelet
// (the same pattern as image_proc's node).
#include <nodelet/loader.h>
#include <ros/ros.h>

int main(int argc, char** argv) {
  ros::init(argc, argv, "klt_contour_tracker");
  nodelet::Loader loader(false);  // no manager services
  const nodelet::M_string remappings(ros::names::getRemappings());
  const nodelet::V_string nodelet_argv(argv + 1, argv + argc);
  if (!loader.load(ros::this_node::getName(), "klt_contour_tracker/TrackerNodelet", remappings,
                   nodelet_argv)) {
    ROS_FATAL("could not load klt_contour_tracker/TrackerNodelet (is the plugin exported?)");
    return 1;
  }
  ros::spin();
  return 0;
}
