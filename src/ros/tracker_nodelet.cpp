#include "klt_contour_tracker/ros/tracker_nodelet.h"

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <pluginlib/class_list_macros.hpp>

#include <chrono>
#include <exception>

#include "klt_contour_tracker/TrackerStatus.h"
#include "klt_contour_tracker/ros/ros_conversions.h"

namespace klt_contour_tracker {
namespace {

double elapsed_ms(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

TrackerNodelet::TrackerNodelet() = default;
TrackerNodelet::~TrackerNodelet() = default;

void TrackerNodelet::onInit() {
  ros::NodeHandle& nh = getNodeHandle();
  ros::NodeHandle& private_nh = getPrivateNodeHandle();
  try {
    config_ = load_config(private_nh);
  } catch (const ConfigError& e) {
    NODELET_FATAL("invalid configuration, not tracking: %s", e.what());
    return;
  }
  for (const std::string& name : unknown_parameters(private_nh))
    NODELET_WARN("parameter %s is not used by this nodelet (typo?)", name.c_str());

  try {
    const std::string path = resolve_mesh_resource(config_.mesh_resource);
    mesh_ = std::make_shared<const kct::Mesh>(kct::load_mesh(path, config_.mesh_scale));
  } catch (const std::exception& e) {
    NODELET_FATAL("invalid configuration, not tracking: ~mesh_resource '%s': %s",
                  config_.mesh_resource.c_str(), e.what());
    return;
  }
  if (mesh_->faces.empty()) {
    NODELET_FATAL("invalid configuration, not tracking: ~mesh_resource '%s' has no faces",
                  config_.mesh_resource.c_str());
    return;
  }
  NODELET_INFO("configuration (mesh: %zu vertices, %zu faces, diameter %.3f m):\n%s",
               mesh_->vertices.size(), mesh_->faces.size(), mesh_->diameter(),
               describe(config_).c_str());

  pose_pub_ = private_nh.advertise<geometry_msgs::PoseStamped>("pose", 10);
  status_pub_ = private_nh.advertise<TrackerStatus>("status", 10);
  tf_broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>();
  image_transport_ = std::make_unique<image_transport::ImageTransport>(nh);
  camera_sub_ = image_transport_->subscribeCamera(
      "image", static_cast<std::uint32_t>(config_.queue_size), &TrackerNodelet::on_image, this,
      image_transport::TransportHints(config_.image_transport, ros::TransportHints(), private_nh));
  NODELET_INFO("waiting for images on %s and %s", camera_sub_.getTopic().c_str(),
               camera_sub_.getInfoTopic().c_str());
}

bool TrackerNodelet::update_camera(const sensor_msgs::CameraInfo& info) {
  if (tracker_ && same_camera(info, camera_info_)) return true;
  kct::PinholeCamera camera;
  try {
    camera = camera_from_info(info);
  } catch (const std::invalid_argument& e) {
    NODELET_ERROR_THROTTLE(5.0, "skipping frame: %s", e.what());
    return false;
  }
  if (!tracker_) {
    // Everything passed to the constructor and to initialize() was validated in onInit().
    tracker_ = std::make_unique<kct::Tracker>(mesh_, camera, config_.params);
    tracker_->initialize(config_.initial_pose);
    NODELET_INFO("tracker started: camera %dx%d, fx %.1f fy %.1f cx %.1f cy %.1f%s",
                 camera.width(), camera.height(), camera.fx(), camera.fy(), camera.cx(),
                 camera.cy(), camera.has_distortion() ? ", undistorting" : "");
  } else {
    tracker_->set_camera(camera);
    NODELET_INFO("camera_info changed: camera %dx%d, fx %.1f fy %.1f cx %.1f cy %.1f",
                 camera.width(), camera.height(), camera.fx(), camera.fy(), camera.cx(),
                 camera.cy());
  }
  camera_info_ = info;
  return true;
}

void TrackerNodelet::on_image(const sensor_msgs::ImageConstPtr& image,
                              const sensor_msgs::CameraInfoConstPtr& info) {
  const auto start = std::chrono::steady_clock::now();
  // A status goes out for every image, also a skipped one (rosbag play --rate-control-topic
  // paces a bag on it, so a missing status would stall the player).
  auto status = boost::make_shared<TrackerStatus>();
  status->header = image->header;
  status->state = kct::to_string(kct::TrackStatus::kInvalidInput);
  auto skip = [&](const std::string& reason) {
    NODELET_WARN_THROTTLE(5.0, "skipping frame: %s", reason.c_str());
    status->message = reason;
  };
  try {
    if (!update_camera(*info)) {
      status->message = "unusable camera_info";
    } else if (static_cast<int>(image->width) != tracker_->camera().width() ||
               static_cast<int>(image->height) != tracker_->camera().height()) {
      skip("image is " + std::to_string(image->width) + "x" + std::to_string(image->height) +
           " but camera_info says " + std::to_string(tracker_->camera().width()) + "x" +
           std::to_string(tracker_->camera().height()));
    } else {
      track(image, *status);
    }
  } catch (const std::exception& e) {
    // Nothing may escape a subscriber callback: it would take the whole manager down.
    NODELET_ERROR_THROTTLE(5.0, "frame %.3f failed: %s", image->header.stamp.toSec(), e.what());
    status->message = e.what();
  }
  status->frame_time_ms = elapsed_ms(start);
  status_pub_.publish(status);
  NODELET_DEBUG("frame %.3f: %s, %d inliers, %.1f ms", image->header.stamp.toSec(),
                status->state.c_str(), status->klt_inliers, status->frame_time_ms);
}

void TrackerNodelet::track(const sensor_msgs::ImageConstPtr& image, TrackerStatus& status) {
  if (!last_stamp_.isZero() && image->header.stamp < last_stamp_) {
    NODELET_INFO("image stamp jumped back from %.3f to %.3f s (bag loop?): re-initializing to "
                 "~initial_pose",
                 last_stamp_.toSec(), image->header.stamp.toSec());
    tracker_->initialize(config_.initial_pose);
  }
  last_stamp_ = image->header.stamp;

  kct::Frame frame;
  try {
    frame.image = image_for_tracker(image);
  } catch (const std::exception& e) {
    NODELET_WARN_THROTTLE(5.0, "skipping frame: %s", e.what());
    status.message = e.what();
    return;
  }
  frame.stamp_s = image->header.stamp.toSec();
  const kct::TrackResult result = tracker_->track(frame);

  status.state = kct::to_string(result.status);
  status.klt_tracked = result.keypoints.tracked;
  status.klt_inliers = result.keypoints.inliers;
  status.extrapolated = result.status == kct::TrackStatus::kExtrapolated;
  status.refined = result.refined;
  status.energy_before = result.energy_before;
  status.energy_after = result.energy_after;
  status.hops = result.hops;
  status.track_time_ms = result.frame_time_ms;
  status.message = result.message;

  if (result.status == kct::TrackStatus::kInvalidInput) {
    NODELET_WARN_THROTTLE(5.0, "skipping frame: %s", result.message.c_str());
    return;
  }
  if (result.status == kct::TrackStatus::kNotInitialized) return;
  if (result.status == kct::TrackStatus::kExtrapolated) {
    NODELET_WARN_THROTTLE(5.0, "keypoint tracking failed (%d tracked, %d inliers): pose "
                               "extrapolated before refinement",
                          result.keypoints.tracked, result.keypoints.inliers);
  }
  auto pose = boost::make_shared<geometry_msgs::PoseStamped>();
  pose->header = image->header;
  pose->pose = to_pose_msg(result.object_to_camera);
  pose_pub_.publish(pose);

  geometry_msgs::TransformStamped transform;
  transform.header = image->header;
  transform.child_frame_id = config_.object_frame;
  transform.transform = to_transform_msg(result.object_to_camera);
  tf_broadcaster_->sendTransform(transform);
}

}  // namespace klt_contour_tracker

PLUGINLIB_EXPORT_CLASS(klt_contour_tracker::TrackerNodelet, nodelet::Nodelet)
