// first_pose: writes the first ground-truth pose of a bag as the tracker nodelet's initial pose
// (a rosparam file), offline (rosbag C++ API, no master).
//
//   first_pose INPUT_BAG [--topic /ground_truth/pose] [--output FILE.yaml]
//
// The pose is object_to_camera in the camera optical frame (metres), as published on the
// ground-truth topic. Without --output the yaml goes to stdout. Exits 1 when the bag has no
// message on the topic.
#include <geometry_msgs/PoseStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>

int main(int argc, char** argv) {
  std::string bag_path, output;
  std::string topic = "/ground_truth/pose";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--topic" && i + 1 < argc) topic = argv[++i];
    else if (arg == "--output" && i + 1 < argc) output = argv[++i];
    else if (bag_path.empty() && arg.rfind("--", 0) != 0) bag_path = arg;
    else {
      std::cerr << "usage: first_pose INPUT_BAG [--topic T] [--output FILE.yaml]\n";
      return 2;
    }
  }
  if (bag_path.empty()) {
    std::cerr << "usage: first_pose INPUT_BAG [--topic T] [--output FILE.yaml]\n";
    return 2;
  }
  geometry_msgs::PoseStamped::ConstPtr first;
  try {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topic))) {
      first = m.instantiate<geometry_msgs::PoseStamped>();
      if (first) break;
    }
  } catch (const rosbag::BagException& e) {
    std::cerr << "first_pose: " << e.what() << "\n";
    return 1;
  }
  if (!first) {
    std::cerr << "first_pose: no geometry_msgs/PoseStamped on " << topic << " in " << bag_path
              << "\n";
    return 1;
  }
  const auto& p = first->pose.position;
  const auto& q = first->pose.orientation;
  std::ostringstream yaml;
  yaml << std::setprecision(10);
  yaml << "# First " << topic << " of " << bag_path << " (stamp " << first->header.stamp
       << ", frame " << first->header.frame_id << "): object_to_camera, optical frame.\n"
       << "initial_pose:\n"
       << "  position: [" << p.x << ", " << p.y << ", " << p.z << "]  # m\n"
       << "  orientation: [" << q.x << ", " << q.y << ", " << q.z << ", " << q.w
       << "]  # quaternion x y z w\n";
  if (output.empty()) {
    std::cout << yaml.str();
  } else {
    std::ofstream file(output);
    file << yaml.str();
    if (!file) {
      std::cerr << "first_pose: cannot write " << output << "\n";
      return 1;
    }
  }
  return 0;
}
