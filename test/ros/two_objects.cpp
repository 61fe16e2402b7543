// rostest: launch/track_two_objects.launch (two nodelets, one manager, one camera; the first
// model from a mesh, the second from a URDF link). Two crates side by side are rendered here;
// each tracker is given its crate's pose through ~init and must follow its own crate, with its
// own object frame in tf.
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "klt_contour_tracker/Init.h"
#include "tracker_harness.h"

#include "ros_test_util.h"

namespace kct_test {
namespace {

class Recorder {
 public:
  void on_pose(const geometry_msgs::PoseStamped::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    poses_.push_back(m);
  }
  std::vector<geometry_msgs::PoseStamped::ConstPtr> poses() {
    std::lock_guard<std::mutex> lock(mutex_);
    return poses_;
  }

 private:
  std::mutex mutex_;
  std::vector<geometry_msgs::PoseStamped::ConstPtr> poses_;
};

TEST(TwoObjects, EachTrackerFollowsItsOwnObject) {
  ros::NodeHandle nh;
  Scene scene;
  kct::Pose truth_a = crate_pose(-0.09, 0.0, 0.5), truth_b = crate_pose(0.09, 0.01, 0.5);
  truth_b.linear() = Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitY()) * truth_b.linear();
  Recorder recorder_a, recorder_b;
  ros::Subscriber sub_a = nh.subscribe("/tracker_a/pose", 100, &Recorder::on_pose, &recorder_a);
  ros::Subscriber sub_b = nh.subscribe("/tracker_b/pose", 100, &Recorder::on_pose, &recorder_b);
  ros::Publisher image_pub = nh.advertise<sensor_msgs::Image>("/two_camera/image_raw", 2);
  ros::Publisher info_pub = nh.advertise<sensor_msgs::CameraInfo>("/two_camera/camera_info", 2);
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  ASSERT_TRUE(ros::service::waitForService("/tracker_a/init", 60000));
  ASSERT_TRUE(ros::service::waitForService("/tracker_b/init", 60000));
  // One connection per topic and process: the manager holding both nodelets.
  ASSERT_TRUE(wait_for([&] { return image_pub.getNumSubscribers() > 0 && info_pub.getNumSubscribers() > 0; }, 30.0));
  ros::WallDuration(1.0).sleep();
  for (const auto& [name, pose] : {std::make_pair(std::string("/tracker_a"), truth_a),
                                   std::make_pair(std::string("/tracker_b"), truth_b)}) {
    klt_contour_tracker::Init srv;
    srv.request.pose.pose = to_pose_msg(pose);
    ASSERT_TRUE(ros::service::call(name + "/init", srv));
    ASSERT_TRUE(srv.response.accepted) << srv.response.message;
  }

  const int frames = 12;
  for (int i = 0; i < frames; ++i) {
    if (i > 0) {
      truth_a = kct::test::move(truth_a, 0.6, {0.0, 1.0, 0.1}, {0.001, 0.0, 0.0});
      truth_b = kct::test::move(truth_b, -0.6, {0.1, 0.0, 1.0}, {0.0, 0.001, 0.0});
    }
    const ros::Time stamp = next_stamp();
    const size_t a_before = recorder_a.poses().size(), b_before = recorder_b.poses().size();
    info_pub.publish(scene.info(stamp));
    image_pub.publish(image_msg(scene.render({truth_a, truth_b}, i), stamp));
    ASSERT_TRUE(wait_for([&] {
      return recorder_a.poses().size() > a_before && recorder_b.poses().size() > b_before;
    }, 120.0)) << "frame " << i;
    const auto a = recorder_a.poses().back(), b = recorder_b.poses().back();
    EXPECT_EQ(a->header.stamp, stamp);
    EXPECT_EQ(b->header.stamp, stamp);
    // Tolerance: 5 mm and 2 deg (keypoints of a 12 cm crate at 0.5 m, 12 frames).
    EXPECT_LT(kct::translation_error(from_pose_msg(a->pose), truth_a), 0.005) << "frame " << i;
    EXPECT_LT(kct::rotation_error_deg(from_pose_msg(a->pose), truth_a), 2.0) << "frame " << i;
    EXPECT_LT(kct::translation_error(from_pose_msg(b->pose), truth_b), 0.005) << "frame " << i;
    EXPECT_LT(kct::rotation_error_deg(from_pose_msg(b->pose), truth_b), 2.0) << "frame " << i;
  }
  // Each has its own tf child frame under the camera frame.
  const ros::Time last = recorder_a.poses().back()->header.stamp;
  ASSERT_TRUE(wait_for([&] {
    return buffer.canTransform(kCameraFrame, "object_a", last) &&
           buffer.canTransform(kCameraFrame, "object_b", last);
  }, 5.0));
  const auto tf_b = buffer.lookupTransform(kCameraFrame, "object_b", last);
  EXPECT_NEAR(tf_b.transform.translation.x, recorder_b.poses().back()->pose.position.x, 1e-9);
  const auto tf_a = buffer.lookupTransform(kCameraFrame, "object_a", last);
  EXPECT_NEAR(tf_a.transform.translation.x, recorder_a.poses().back()->pose.position.x, 1e-9);
}

}  // namespace
}  // namespace kct_test

KCT_ROSTEST_MAIN("two_objects_test")
