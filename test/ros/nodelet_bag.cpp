// rostest: the tracker nodelet on a generated 40-frame bag. The test node loads the nodelet into
// the manager of nodelet_bag.test (parameters set here, initial pose = the bag's first ground
// truth), then publishes the bag's frames one at a time, each after the previous one was
// processed, so that no frame can be dropped and the result does not depend on timing.
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <mutex>
#include <string>
#include <vector>

#include "klt_contour_tracker/TrackerStatus.h"
#include "klt_contour_tracker/core/pose.h"

#include "klt_contour_tracker/ros/ros_conversions.h"
#include "ros_test_util.h"

namespace {

// Accuracy required on every frame of the synthetic sequence (ground truth is exact): 10 mm and
// 3 deg with the contour refinement (`paper`, the default of nodelet_bag.test; measured: 3.7 mm,
// 2.8 deg). Keypoints alone (`klt_only`, `rostest ... preset:=klt_only`) drift slowly in
// rotation (3.8 deg by frame 40 of this sequence), so that baseline gets 5 deg.
constexpr double kMaxTranslationErrorMm = 10.0;
double max_rotation_error_deg(const std::string& preset) { return preset == "klt_only" ? 5.0 : 3.0; }
// Generous: the first frame also builds the tracker (visibility table for the paper preset).
const ros::WallDuration kFrameTimeout(120.0);

using klt_contour_tracker::from_pose_msg;

class Recorder {
 public:
  void on_pose(const geometry_msgs::PoseStamped::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    poses_.push_back(msg);
  }
  void on_status(const klt_contour_tracker::TrackerStatus::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    statuses_.push_back(msg);
  }
  size_t status_count() {
    std::lock_guard<std::mutex> lock(mutex_);
    return statuses_.size();
  }
  std::vector<geometry_msgs::PoseStamped::ConstPtr> poses() {
    std::lock_guard<std::mutex> lock(mutex_);
    return poses_;
  }
  std::vector<klt_contour_tracker::TrackerStatus::ConstPtr> statuses() {
    std::lock_guard<std::mutex> lock(mutex_);
    return statuses_;
  }

 private:
  std::mutex mutex_;
  std::vector<geometry_msgs::PoseStamped::ConstPtr> poses_;
  std::vector<klt_contour_tracker::TrackerStatus::ConstPtr> statuses_;
};

TEST(NodeletBag, PublishesAnAccuratePoseForEveryFrame) {
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  std::string bag_path, preset;
  // Default: the bag the `tests` target generates (see CMakeLists.txt).
  private_nh.param<std::string>("bag", bag_path, KCT_TEST_DATA_DIR "/small.bag");
  private_nh.param<std::string>("preset", preset, "paper");
  const std::vector<BagFrame> frames = read_bag(bag_path);
  ASSERT_GE(frames.size(), 10u) << bag_path;
  const double max_r_allowed_deg = max_rotation_error_deg(preset);
  for (const BagFrame& f : frames) {
    ASSERT_TRUE(f.image && f.info && f.ground_truth)
        << "bag frame without image, camera_info or ground truth";
  }

  // Configure and load the nodelet: name /klt_contour_tracker, camera in /camera.
  const std::string name = "/klt_contour_tracker";
  const geometry_msgs::Pose& first = frames.front().ground_truth->pose;
  nh.setParam(name + "/preset", preset);
  nh.setParam(name + "/queue_size", 5);
  set_demo_crate_params(name, first);
  ASSERT_TRUE(load_tracker_nodelet(name));

  Recorder recorder;
  ros::Subscriber pose_sub = nh.subscribe(name + "/pose", 100, &Recorder::on_pose, &recorder);
  ros::Subscriber status_sub =
      nh.subscribe(name + "/status", 100, &Recorder::on_status, &recorder);
  ros::Publisher image_pub = nh.advertise<sensor_msgs::Image>("/camera/image_raw", 1);
  ros::Publisher info_pub = nh.advertise<sensor_msgs::CameraInfo>("/camera/camera_info", 1);
  tf2_ros::Buffer tf_buffer;
  tf2_ros::TransformListener tf_listener(tf_buffer);
  ASSERT_TRUE(wait_for(
      [&] {
        return image_pub.getNumSubscribers() > 0 && info_pub.getNumSubscribers() > 0 &&
               pose_sub.getNumPublishers() > 0 && status_sub.getNumPublishers() > 0;
      },
      30.0))
      << "the nodelet did not connect";

  // One frame at a time: publish, wait for its status (published for every processed frame).
  auto play = [&](const BagFrame& frame) {
    const size_t before = recorder.status_count();
    info_pub.publish(frame.info);
    image_pub.publish(frame.image);
    return wait_for([&] { return recorder.status_count() > before; }, kFrameTimeout.toSec());
  };
  for (size_t i = 0; i < frames.size(); ++i) {
    ASSERT_TRUE(play(frames[i])) << "no status for frame " << i << " within "
                                 << kFrameTimeout.toSec() << " s";
  }

  const auto poses = recorder.poses();
  const auto statuses = recorder.statuses();
  ASSERT_EQ(poses.size(), frames.size()) << "one PoseStamped per image";
  ASSERT_EQ(statuses.size(), frames.size());
  double max_t_mm = 0.0, max_r_deg = 0.0;
  for (size_t i = 0; i < frames.size(); ++i) {
    const std_msgs::Header& image_header = frames[i].image->header;
    EXPECT_EQ(poses[i]->header.stamp, image_header.stamp) << "frame " << i;
    EXPECT_EQ(poses[i]->header.frame_id, image_header.frame_id) << "frame " << i;
    EXPECT_EQ(statuses[i]->header.stamp, image_header.stamp) << "frame " << i;
    EXPECT_NE(statuses[i]->state, "invalid_input") << statuses[i]->message;
    const kct::Pose estimate = from_pose_msg(poses[i]->pose);
    const kct::Pose truth = from_pose_msg(frames[i].ground_truth->pose);
    const double t_mm = 1000.0 * kct::translation_error(estimate, truth);
    const double r_deg = kct::rotation_error_deg(estimate, truth);
    EXPECT_LT(t_mm, kMaxTranslationErrorMm) << "frame " << i;
    EXPECT_LT(r_deg, max_r_allowed_deg) << "frame " << i;
    max_t_mm = std::max(max_t_mm, t_mm);
    max_r_deg = std::max(max_r_deg, r_deg);
  }
  std::printf("[nodelet_bag] %zu frames, preset %s: max error %.2f mm, %.3f deg\n",
              frames.size(), preset.c_str(), max_t_mm, max_r_deg);

  // tf: image frame -> object at the last stamp, equal to the last PoseStamped.
  const std_msgs::Header& last_header = frames.back().image->header;
  geometry_msgs::TransformStamped tf_msg;
  ASSERT_TRUE(wait_for(
      [&] { return tf_buffer.canTransform(last_header.frame_id, "object", last_header.stamp); },
      5.0));
  tf_msg = tf_buffer.lookupTransform(last_header.frame_id, "object", last_header.stamp);
  const geometry_msgs::Pose& last_pose = poses.back()->pose;
  EXPECT_NEAR(tf_msg.transform.translation.x, last_pose.position.x, 1e-9);
  EXPECT_NEAR(tf_msg.transform.translation.y, last_pose.position.y, 1e-9);
  EXPECT_NEAR(tf_msg.transform.translation.z, last_pose.position.z, 1e-9);
  EXPECT_NEAR(std::abs(tf_msg.transform.rotation.w), std::abs(last_pose.orientation.w), 1e-9);

  // A backward jump of the stamp (a looping bag) re-initializes to ~initial_pose.
  ASSERT_TRUE(play(frames.front()));
  const auto after_loop = recorder.poses();
  ASSERT_EQ(after_loop.size(), frames.size() + 1);
  const kct::Pose reinitialized = from_pose_msg(after_loop.back()->pose);
  EXPECT_LT(1000.0 * kct::translation_error(reinitialized, from_pose_msg(first)), 1e-3);
  EXPECT_LT(kct::rotation_error_deg(reinitialized, from_pose_msg(first)), 1e-3);
}

}  // namespace

KCT_ROSTEST_MAIN("nodelet_bag_test")
