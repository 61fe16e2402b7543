// evaluate_bag: compares the tracker's published poses with the ground truth, offline (rosbag
// C++ API, no master). Poses are matched to ground-truth poses by header stamp.
//
//   evaluate_bag TRACKED_BAG [--ground-truth INPUT_BAG] [--pose-topic T] [--status-topic T]
//                [--gt-topic T]
//
// TRACKED_BAG holds the nodelet's PoseStamped (default /klt_contour_tracker/pose) and
// TrackerStatus (/klt_contour_tracker/status); the ground truth (/ground_truth/pose,
// object_to_camera PoseStamped) is read from INPUT_BAG when given (the bag that was played:
// every frame of the sequence), otherwise from TRACKED_BAG. Prints a summary block; exits 1 when
// a bag cannot be read or holds no ground truth.
#include <geometry_msgs/PoseStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "klt_contour_tracker/TrackerStatus.h"
#include "klt_contour_tracker/core/pose.h"

namespace {

kct::Pose to_pose(const geometry_msgs::Pose& p) {
  return kct::pose_from_quaternion(p.position.x, p.position.y, p.position.z, p.orientation.x,
                                   p.orientation.y, p.orientation.z, p.orientation.w);
}

std::map<ros::Time, kct::Pose> read_poses(const std::string& path, const std::string& topic) {
  std::map<ros::Time, kct::Pose> poses;
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topic))) {
    if (auto msg = m.instantiate<geometry_msgs::PoseStamped>())
      poses[msg->header.stamp] = to_pose(msg->pose);
  }
  return poses;
}

double median(std::vector<double> values) {
  if (values.empty()) return std::nan("");
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

void usage() {
  std::cerr << "usage: evaluate_bag TRACKED_BAG [--ground-truth INPUT_BAG] [--pose-topic T]"
               " [--status-topic T] [--gt-topic T]\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::string tracked_bag, gt_bag;
  std::string pose_topic = "/klt_contour_tracker/pose";
  std::string status_topic = "/klt_contour_tracker/status";
  std::string gt_topic = "/ground_truth/pose";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        usage();
        std::exit(2);
      }
      return argv[++i];
    };
    if (arg == "--ground-truth") gt_bag = value();
    else if (arg == "--pose-topic") pose_topic = value();
    else if (arg == "--status-topic") status_topic = value();
    else if (arg == "--gt-topic") gt_topic = value();
    else if (arg == "-h" || arg == "--help") { usage(); return 0; }
    else if (tracked_bag.empty() && arg.rfind("--", 0) != 0) tracked_bag = arg;
    else { usage(); return 2; }
  }
  if (tracked_bag.empty()) { usage(); return 2; }
  if (gt_bag.empty()) gt_bag = tracked_bag;

  std::map<ros::Time, kct::Pose> ground_truth, tracked;
  std::vector<double> frame_times_ms, track_times_ms;
  std::map<std::string, int> states;
  try {
    ground_truth = read_poses(gt_bag, gt_topic);
    tracked = read_poses(tracked_bag, pose_topic);
    rosbag::Bag bag(tracked_bag, rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(status_topic))) {
      if (auto s = m.instantiate<klt_contour_tracker::TrackerStatus>()) {
        frame_times_ms.push_back(s->frame_time_ms);
        track_times_ms.push_back(s->track_time_ms);
        ++states[s->state];
      }
    }
  } catch (const rosbag::BagException& e) {
    std::cerr << "evaluate_bag: " << e.what() << "\n";
    return 1;
  }
  if (ground_truth.empty()) {
    std::cerr << "evaluate_bag: no " << gt_topic << " messages in " << gt_bag << "\n";
    return 1;
  }

  // Stamps are copied from the image header, so a match is exact; 1 ms absorbs float round trips.
  const ros::Duration tolerance(0.001);
  int matched = 0;
  double sum_t_mm = 0.0, sum_r_deg = 0.0, max_t_mm = 0.0, max_r_deg = 0.0;
  double final_t_mm = std::nan(""), final_r_deg = std::nan("");
  bool last_frame_has_pose = false;
  for (const auto& [stamp, gt] : ground_truth) {
    auto it = tracked.lower_bound(stamp - tolerance);
    last_frame_has_pose = it != tracked.end() && it->first <= stamp + tolerance;
    if (!last_frame_has_pose) continue;
    const double t_mm = 1000.0 * kct::translation_error(it->second, gt);
    const double r_deg = kct::rotation_error_deg(it->second, gt);
    ++matched;
    sum_t_mm += t_mm;
    sum_r_deg += r_deg;
    max_t_mm = std::max(max_t_mm, t_mm);
    max_r_deg = std::max(max_r_deg, r_deg);
    final_t_mm = t_mm;
    final_r_deg = r_deg;
  }

  const int frames = static_cast<int>(ground_truth.size());
  std::string state_counts;
  for (const auto& [state, count] : states)
    state_counts += (state_counts.empty() ? "" : ", ") + state + " " + std::to_string(count);
  std::printf("================ klt_contour_tracker evaluation ================\n");
  std::printf("ground truth         : %s (%s)\n", gt_bag.c_str(), gt_topic.c_str());
  std::printf("tracker output       : %s (%s)\n", tracked_bag.c_str(), pose_topic.c_str());
  std::printf("frames received      : %d (ground-truth frames)\n", frames);
  std::printf("frames with a pose   : %d (%.1f %%)\n", matched, 100.0 * matched / frames);
  if (matched > 0) {
    std::printf("translation error    : mean %.2f mm, max %.2f mm, final %.2f mm%s\n",
                sum_t_mm / matched, max_t_mm, final_t_mm,
                last_frame_has_pose ? "" : " (last frame had no pose)");
    std::printf("rotation error       : mean %.3f deg, max %.3f deg, final %.3f deg\n",
                sum_r_deg / matched, max_r_deg, final_r_deg);
  }
  if (!frame_times_ms.empty()) {
    std::printf("frame time           : median %.1f ms (callback), median %.1f ms in "
                "Tracker::track, %zu status messages\n",
                median(frame_times_ms), median(track_times_ms), frame_times_ms.size());
    std::printf("frame states         : %s\n", state_counts.c_str());
  } else {
    std::printf("frame time           : no %s messages\n", status_topic.c_str());
  }
  std::printf("================================================================\n");
  return 0;
}
