// rostest: the nodelet's ROS interface on frames rendered here (tracker_harness.h):
// ~init / ~initial_pose / ~reset, an initial pose in a world frame through tf, LOST and
// re-acquisition when the object is hidden for a stretch of frames, and bad input (each reported
// in ~status while the node keeps tracking the next good frame).
#include <diagnostic_msgs/DiagnosticArray.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <geometry_msgs/TransformStamped.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <limits>

#include "klt_contour_tracker/Init.h"
#include "tracker_harness.h"

#include "ros_test_util.h"

namespace kct_test {
namespace {

using klt_contour_tracker::TrackerStatus;

/// The klt_only nodelet "/tracker" without an initial pose parameter, shared by the tests below
/// (they run in order: it is in a known state at the start of each).
struct Shared {
  Scene scene;
  Harness harness{"tracker", {{"mesh_resource", XmlRpc::XmlRpcValue("file://" + kMeshPath)},
                              {"preset", XmlRpc::XmlRpcValue("klt_only")},
                              {"object_frame", XmlRpc::XmlRpcValue("crate")}}};
  kct::Pose truth = crate_pose();
  int seed = 0;

  /// The crate at `truth` moved by a small step (so that KLT has motion to follow).
  TrackerStatus::ConstPtr step(bool move = true) {
    if (move) truth = kct::test::move(truth, 0.5, {0.1, 1.0, 0.0}, {0.001, 0.0, 0.0});
    const ros::Time stamp = next_stamp();
    return harness.send(image_msg(scene.render({truth}, ++seed), stamp), scene.info(stamp));
  }
};

Shared& shared() {
  static Shared s;
  return s;
}

bool call_init(const std::string& name, const geometry_msgs::PoseStamped& pose,
               klt_contour_tracker::Init::Response& response) {
  klt_contour_tracker::Init srv;
  srv.request.pose = pose;
  const bool called = ros::service::call(name + "/init", srv);
  response = srv.response;
  return called;
}

geometry_msgs::PoseStamped stamped(const kct::Pose& pose, const std::string& frame = "") {
  geometry_msgs::PoseStamped m;
  m.header.frame_id = frame;
  m.pose = to_pose_msg(pose);
  return m;
}

// After bad input: the next good frame is tracked and its pose published.
void expect_recovers_on_the_next_good_frame() {
  const auto status = shared().step();
  ASSERT_TRUE(status);
  EXPECT_EQ(status->state, "keypoints") << status->message;
  EXPECT_EQ(status->tracking_state, "tracking");
  EXPECT_TRUE(status->pose_published);
  const auto pose = shared().harness.last_pose();
  ASSERT_TRUE(pose);
  EXPECT_EQ(pose->header.stamp, status->header.stamp);
  EXPECT_LT(kct::translation_error(from_pose_msg(pose->pose), shared().truth), 0.005);
}

TEST(TrackerInterface, WaitsForAPoseThenTheInitServiceStartsTracking) {
  Shared& s = shared();
  ASSERT_TRUE(s.harness.ready());
  ASSERT_TRUE(ros::service::waitForService("/tracker/init", 30000));
  const auto waiting = s.step(false);
  ASSERT_TRUE(waiting);
  EXPECT_EQ(waiting->tracking_state, "waiting_for_pose");
  EXPECT_EQ(waiting->state, "not_initialized");
  EXPECT_FALSE(waiting->pose_published);
  EXPECT_TRUE(s.harness.poses().empty());

  klt_contour_tracker::Init::Response response;
  ASSERT_TRUE(call_init("/tracker", stamped(s.truth), response));
  EXPECT_TRUE(response.accepted) << response.message;
  const auto first = s.step(false);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->state, "initialized");
  EXPECT_EQ(first->tracking_state, "tracking");
  ASSERT_TRUE(first->pose_published);
  EXPECT_LT(kct::translation_error(from_pose_msg(s.harness.last_pose()->pose), s.truth), 1e-6);
  for (int i = 0; i < 5; ++i) {
    const auto status = s.step();
    ASSERT_TRUE(status);
    EXPECT_EQ(status->state, "keypoints") << i;
    EXPECT_GT(status->quality, 0.5) << i;
    EXPECT_LT(kct::translation_error(from_pose_msg(s.harness.last_pose()->pose), s.truth), 0.005) << i;
    EXPECT_LT(kct::rotation_error_deg(from_pose_msg(s.harness.last_pose()->pose), s.truth), 2.0) << i;
  }
  // ~pose_with_covariance: same stamp and pose, a positive-definite covariance with depth the
  // least certain translation (a small object seen from 0.45 m).
  const auto covariance = s.harness.covariances();
  ASSERT_FALSE(covariance.empty());
  const auto& last = covariance.back();
  EXPECT_EQ(last->header.stamp, s.harness.last_pose()->header.stamp);
  EXPECT_EQ(last->header.frame_id, kCameraFrame);
  EXPECT_NEAR(last->pose.pose.position.z, s.harness.last_pose()->pose.position.z, 1e-12);
  for (int i = 0; i < 6; ++i) EXPECT_GT(last->pose.covariance[7 * i], 0.0) << i;
  EXPECT_GT(last->pose.covariance[14], last->pose.covariance[0]);
}

TEST(TrackerInterface, ResetWaitsForAPoseAndTheInitialPoseTopicRestarts) {
  Shared& s = shared();
  ASSERT_TRUE(s.harness.ready());
  std_srvs::Trigger trigger;
  ASSERT_TRUE(ros::service::call("/tracker/reset", trigger));
  EXPECT_TRUE(trigger.response.success);
  const size_t poses_before = s.harness.poses().size();
  for (int i = 0; i < 2; ++i) {
    const auto status = s.step();
    ASSERT_TRUE(status);
    EXPECT_EQ(status->tracking_state, "waiting_for_pose");
    EXPECT_FALSE(status->pose_published);
  }
  EXPECT_EQ(s.harness.poses().size(), poses_before);

  ros::NodeHandle nh;
  ros::Publisher initial = nh.advertise<geometry_msgs::PoseStamped>("/tracker/initial_pose", 1, true);
  ASSERT_TRUE(wait_for([&] { return initial.getNumSubscribers() > 0; }, 10.0));
  initial.publish(stamped(s.truth));
  ros::WallDuration(0.5).sleep();  // the pose and the image travel on different connections
  const auto status = s.step(false);
  ASSERT_TRUE(status);
  EXPECT_EQ(status->state, "initialized");
  EXPECT_EQ(status->tracking_state, "tracking");
  expect_recovers_on_the_next_good_frame();
}

TEST(TrackerInterface, InitialPoseInAWorldFrameIsTransformedThroughTf) {
  Shared& s = shared();
  ASSERT_TRUE(s.harness.ready());
  // world -> camera_optical: the camera 1 m above the world origin, looking along world x.
  kct::Pose world_to_camera_optical = kct::Pose::Identity();  // camera pose in the world
  world_to_camera_optical.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  world_to_camera_optical.translation() = Eigen::Vector3d(0.2, -0.1, 1.0);
  tf2_ros::StaticTransformBroadcaster static_broadcaster;
  geometry_msgs::TransformStamped t;
  t.header.frame_id = "world";
  t.child_frame_id = kCameraFrame;
  const geometry_msgs::Pose p = to_pose_msg(world_to_camera_optical);
  t.transform.translation.x = p.position.x;
  t.transform.translation.y = p.position.y;
  t.transform.translation.z = p.position.z;
  t.transform.rotation = p.orientation;
  static_broadcaster.sendTransform(t);
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  ros::WallDuration(1.0).sleep();  // the static transform reaches the nodelet's listener

  const kct::Pose object_in_world = world_to_camera_optical * s.truth;
  klt_contour_tracker::Init::Response response;
  ASSERT_TRUE(call_init("/tracker", stamped(object_in_world, "world"), response));
  EXPECT_TRUE(response.accepted) << response.message;
  const auto status = s.step(false);
  ASSERT_TRUE(status);
  EXPECT_EQ(status->state, "initialized");
  const auto pose = s.harness.last_pose();
  ASSERT_TRUE(pose);
  EXPECT_EQ(pose->header.frame_id, kCameraFrame);
  EXPECT_LT(kct::translation_error(from_pose_msg(pose->pose), s.truth), 1e-6);
  EXPECT_LT(kct::rotation_error_deg(from_pose_msg(pose->pose), s.truth), 1e-4);
  // And the published tf chains back into the world frame.
  ASSERT_TRUE(wait_for([&] { return buffer.canTransform("world", "crate", status->header.stamp); }, 5.0));
  const auto world_to_object = buffer.lookupTransform("world", "crate", status->header.stamp);
  EXPECT_NEAR(world_to_object.transform.translation.x, object_in_world.translation().x(), 1e-6);
  EXPECT_NEAR(world_to_object.transform.translation.y, object_in_world.translation().y(), 1e-6);
  EXPECT_NEAR(world_to_object.transform.translation.z, object_in_world.translation().z(), 1e-6);
  // A frame tf does not know is rejected.
  ASSERT_TRUE(call_init("/tracker", stamped(object_in_world, "no_such_frame"), response));
  EXPECT_FALSE(response.accepted);
  EXPECT_NE(response.message.find("no_such_frame"), std::string::npos) << response.message;
  expect_recovers_on_the_next_good_frame();
}

TEST(TrackerInterface, NanInitialPoseIsRejected) {
  Shared& s = shared();
  ASSERT_TRUE(s.harness.ready());
  kct::Pose nan_pose = s.truth;
  geometry_msgs::PoseStamped m = stamped(nan_pose);
  m.pose.position.x = std::numeric_limits<double>::quiet_NaN();
  klt_contour_tracker::Init::Response response;
  ASSERT_TRUE(call_init("/tracker", m, response));
  EXPECT_FALSE(response.accepted);
  EXPECT_NE(response.message.find("finite"), std::string::npos) << response.message;
  expect_recovers_on_the_next_good_frame();
}

TEST(TrackerInterface, PoseBehindTheCameraIsRejected) {
  Shared& s = shared();
  ASSERT_TRUE(s.harness.ready());
  kct::Pose behind = s.truth;
  behind.translation().z() = -0.45;
  klt_contour_tracker::Init::Response response;
  ASSERT_TRUE(call_init("/tracker", stamped(behind), response));
  EXPECT_FALSE(response.accepted);
  EXPECT_NE(response.message.find("behind"), std::string::npos) << response.message;
  expect_recovers_on_the_next_good_frame();
}

// Bad input: one frame, reported in its status; the next good frame is tracked.
void expect_invalid(const sensor_msgs::ImagePtr& image, const sensor_msgs::CameraInfo& info,
                    const std::string& message_part) {
  const auto status = shared().harness.send(image, info);
  ASSERT_TRUE(status) << "no status for a bad frame: the node stopped?";
  EXPECT_EQ(status->state, "invalid_input");
  EXPECT_FALSE(status->pose_published);
  EXPECT_EQ(status->header.stamp, image->header.stamp);
  EXPECT_NE(status->message.find(message_part), std::string::npos) << status->message;
  expect_recovers_on_the_next_good_frame();
}

TEST(TrackerInterface, EmptyImage) {
  ASSERT_TRUE(shared().harness.ready());
  const ros::Time stamp = next_stamp();
  expect_invalid(image_msg(cv::Mat(0, 0, CV_8UC3), stamp), shared().scene.info(stamp), "0x0");
}

TEST(TrackerInterface, ImageSizeDiffersFromCameraInfo) {
  ASSERT_TRUE(shared().harness.ready());
  const ros::Time stamp = next_stamp();
  expect_invalid(image_msg(cv::Mat(240, 320, CV_8UC3, cv::Scalar(90, 90, 90)), stamp),
                 shared().scene.info(stamp), "320x240");
}

TEST(TrackerInterface, UnknownEncoding) {
  ASSERT_TRUE(shared().harness.ready());
  const ros::Time stamp = next_stamp();
  auto image = image_msg(cv::Mat(480, 640, CV_8UC3, cv::Scalar(90, 90, 90)), stamp);
  image->encoding = "32FC1";
  image->step = 640 * 4;
  image->data.resize(640 * 480 * 4);
  expect_invalid(image, shared().scene.info(stamp), "32FC1");
}

TEST(TrackerInterface, CameraInfoWithKAllZero) {
  ASSERT_TRUE(shared().harness.ready());
  const ros::Time stamp = next_stamp();
  sensor_msgs::CameraInfo info = shared().scene.info(stamp);
  info.K.fill(0.0);
  info.P.fill(0.0);
  expect_invalid(image_msg(shared().scene.render({shared().truth}, 99), stamp), info, "all zero");
}

// LOST and re-acquisition: a paper-preset nodelet (coarse visibility table for speed) tracks the
// crate for 8 frames; the crate is hidden for 8 frames, then reappears 6 mm and 3 deg away from
// where it vanished and stays there.
TEST(TrackerInterface, LostWhileHiddenAndReacquiredWhenTheObjectComesBack) {
  Scene scene;
  kct::Pose truth = crate_pose(0.01, 0.0, 0.45);
  std::map<std::string, XmlRpc::XmlRpcValue> params = {
      {"mesh_resource", XmlRpc::XmlRpcValue("file://" + kMeshPath)},
      {"preset", XmlRpc::XmlRpcValue("paper")},
      {"icosphere_subdivisions", XmlRpc::XmlRpcValue(2)},
      {"visibility_resolution_px", XmlRpc::XmlRpcValue(128)},
      {"lost_after_bad_frames", XmlRpc::XmlRpcValue(4)},  // not the default (3)
      {"recover_after_good_frames", XmlRpc::XmlRpcValue(2)},
      {"object_frame", XmlRpc::XmlRpcValue("crate_lost")}};
  set_initial_pose(params, truth);
  Harness harness("tracker_lost", params);
  ASSERT_TRUE(harness.ready());

  std::vector<TrackerStatus::ConstPtr> statuses;
  auto send = [&](bool visible, int seed) {
    const ros::Time stamp = next_stamp();
    const cv::Mat frame = visible ? scene.render({truth}, seed) : scene.render({}, seed);
    const auto status = harness.send(image_msg(frame, stamp), scene.info(stamp), 300.0);
    EXPECT_TRUE(status) << "frame " << seed;
    if (status) statuses.push_back(status);
    return status;
  };
  for (int i = 0; i < 8; ++i) {
    if (i > 0) truth = kct::test::move(truth, 0.5, {0.0, 1.0, 0.2}, {0.001, 0.0, 0.0});
    const auto status = send(true, i);
    ASSERT_TRUE(status);
    EXPECT_EQ(status->tracking_state, "tracking") << "frame " << i;
    EXPECT_TRUE(status->good) << "frame " << i << " quality " << status->quality;
  }
  EXPECT_LT(kct::translation_error(from_pose_msg(harness.last_pose()->pose), truth), 0.005);
  const size_t poses_before_hiding = harness.poses().size();

  int lost_at = -1;
  for (int i = 0; i < 8; ++i) {
    const auto status = send(false, 100 + i);
    ASSERT_TRUE(status);
    EXPECT_FALSE(status->good) << "hidden frame " << i << " quality " << status->quality;
    if (status->tracking_state == "lost" && lost_at < 0) lost_at = i;
    if (status->tracking_state == "lost") {
      EXPECT_FALSE(status->pose_published) << "hidden frame " << i;
    }
  }
  EXPECT_EQ(lost_at, 3) << "LOST on the fourth bad frame (~lost_after_bad_frames 4)";
  EXPECT_LE(harness.poses().size(), poses_before_hiding + 3);

  truth = kct::test::move(truth, 3.0, {0.2, 1.0, 0.0}, {0.006, -0.002, 0.0});
  int tracking_again_at = -1;
  bool reacquired = false;
  for (int i = 0; i < 10; ++i) {
    const auto status = send(true, 200 + i);
    ASSERT_TRUE(status);
    reacquired = reacquired || status->state == "reacquired";
    if (status->tracking_state == "tracking" && tracking_again_at < 0) tracking_again_at = i;
  }
  EXPECT_TRUE(reacquired);
  EXPECT_GE(tracking_again_at, 1);
  EXPECT_LE(tracking_again_at, 4);
  ASSERT_EQ(statuses.back()->tracking_state, "tracking");
  EXPECT_TRUE(statuses.back()->pose_published);
  const kct::Pose final_pose = from_pose_msg(harness.last_pose()->pose);
  EXPECT_EQ(harness.last_pose()->header.stamp, statuses.back()->header.stamp);
  // Tolerance: 5 mm and 3 deg after re-acquisition (coarse visibility table).
  EXPECT_LT(kct::translation_error(final_pose, truth), 0.005);
  EXPECT_LT(kct::rotation_error_deg(final_pose, truth), 3.0);

  // dynamic_reconfigure: choosing a preset pushes its values back (klt_only: no refinement);
  // an invalid value (an even KLT window) is rejected and the values in use are shown.
  auto reconfigure = [&](const std::function<void(dynamic_reconfigure::Config&)>& fill) {
    dynamic_reconfigure::Reconfigure srv;
    fill(srv.request.config);
    EXPECT_TRUE(ros::service::call(harness.name() + "/set_parameters", srv));
    return srv.response.config;
  };
  auto find_bool = [](const dynamic_reconfigure::Config& c, const std::string& name) {
    for (const auto& b : c.bools) if (b.name == name) return static_cast<int>(b.value);
    return -1;
  };
  auto find_int = [](const dynamic_reconfigure::Config& c, const std::string& name) {
    for (const auto& i : c.ints) if (i.name == name) return i.value;
    return -1;
  };
  dynamic_reconfigure::Config config = reconfigure([](dynamic_reconfigure::Config& c) {
    dynamic_reconfigure::StrParameter preset;
    preset.name = "preset";
    preset.value = "klt_only";
    c.strs.push_back(preset);
  });
  EXPECT_EQ(find_bool(config, "refine"), 0) << "the klt_only preset was not pushed back";
  config = reconfigure([](dynamic_reconfigure::Config& c) {
    dynamic_reconfigure::IntParameter window;
    window.name = "klt_window_px";
    window.value = 16;
    c.ints.push_back(window);
  });
  EXPECT_EQ(find_int(config, "klt_window_px"), 21) << "an even KLT window must be rejected";
  const auto after = send(true, 300);
  ASSERT_TRUE(after);
  EXPECT_FALSE(after->refined);
  EXPECT_EQ(after->state, "keypoints");
}

// /diagnostics: the tracking state and the ~pose topic's rate and stamp age.
TEST(TrackerInterface, DiagnosticsReportTheStateAndThePoseTopic) {
  Shared& s = shared();
  ASSERT_TRUE(s.harness.ready());
  std::mutex mutex;
  std::map<std::string, diagnostic_msgs::DiagnosticStatus> latest;
  ros::NodeHandle nh;
  ros::Subscriber sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 10, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        for (const auto& status : m->status) latest[status.name] = status;
      });
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(s.step());
  ASSERT_TRUE(wait_for([&] {
    std::lock_guard<std::mutex> lock(mutex);
    return latest.count("tracker: tracking") && latest.count("tracker: pose topic status");
  }, 10.0));
  std::lock_guard<std::mutex> lock(mutex);
  const auto& tracking = latest.at("tracker: tracking");
  EXPECT_EQ(tracking.level, diagnostic_msgs::DiagnosticStatus::OK) << tracking.message;
  EXPECT_EQ(tracking.hardware_id, "crate");
  bool has_state = false;
  for (const auto& kv : tracking.values)
    if (kv.key == "state") has_state = kv.value == "tracking";
  EXPECT_TRUE(has_state);
  bool has_rate = false;
  for (const auto& kv : latest.at("tracker: pose topic status").values)
    has_rate = has_rate || kv.key.find("frequency") != std::string::npos ||
               kv.key.find("Frequency") != std::string::npos;
  EXPECT_TRUE(has_rate);
}

}  // namespace
}  // namespace kct_test

KCT_ROSTEST_MAIN("tracker_interface_test")
