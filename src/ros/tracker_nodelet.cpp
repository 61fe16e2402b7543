#include "klt_contour_tracker/ros/tracker_nodelet.h"

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <image_transport/camera_common.h>
#include <pluginlib/class_list_macros.hpp>
#include <visualization_msgs/Marker.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cv_bridge/cv_bridge.h>
#include <exception>
#include <opencv2/imgproc.hpp>

#include "klt_contour_tracker/core/debug_drawing.h"
#include "klt_contour_tracker/core/elapsed.h"
#include "klt_contour_tracker/core/plausibility.h"
#include "klt_contour_tracker/core/pose_covariance.h"
#include "klt_contour_tracker/ros/camera_conversion.h"
#include "klt_contour_tracker/ros/model_loader.h"
#include "klt_contour_tracker/ros/ros_conversions.h"

namespace klt_contour_tracker {
namespace {

/// Latest image stamp accepted, s (2100-01-01T00:00:00Z; ROS 1 time ends at 2^32 s in 2106).
constexpr std::uint32_t kLastStampSec = 4102444800u;

/// A mesh URL RViz can load for ~mesh_resource, "" when there is none (URDF model or a remote
/// resource): then the marker is a triangle list.
std::string rviz_mesh_url(const NodeletConfig& config) {
  if (!config.model_description.empty()) return "";
  const std::string& r = config.mesh_resource;
  if (r.rfind("package://", 0) == 0 || r.rfind("file://", 0) == 0) return r;
  if (!r.empty() && r[0] == '/') return "file://" + r;
  return "";
}

}  // namespace

TrackerNodelet::TrackerNodelet() = default;
TrackerNodelet::~TrackerNodelet() = default;

void TrackerNodelet::onInit() {
  ros::NodeHandle& nh = getNodeHandle();
  ros::NodeHandle& private_nh = getPrivateNodeHandle();
  try {
    config_ = load_config(private_nh);
    interface_ = load_interface_config(private_nh);
  } catch (const ConfigError& e) {
    NODELET_FATAL("invalid configuration, not tracking: %s", e.what());
    return;
  }
  const std::vector<std::string> ours = interface_parameter_names();
  for (const std::string& name : unknown_parameters(private_nh)) {
    if (std::find(ours.begin(), ours.end(), name.substr(1)) == ours.end())
      NODELET_WARN("parameter %s is not used by this nodelet (typo?)", name.c_str());
  }

  try {
    mesh_ = std::make_shared<const kct::Mesh>(load_model(config_));
    session_ = std::make_unique<kct::TrackingSession>(mesh_, config_.params, interface_.quality);
  } catch (const std::exception& e) {
    NODELET_FATAL("invalid configuration, not tracking: %s", e.what());
    return;
  }
  NODELET_INFO("configuration (mesh: %zu vertices, %zu faces, diameter %.3f m):\n%s%s",
               mesh_->vertices.size(), mesh_->faces.size(), mesh_->diameter(),
               describe(config_).c_str(), describe(interface_).c_str());

  if (interface_.has_initial_pose) {
    session_->set_restart_pose(config_.initial_pose);
    geometry_msgs::PoseStamped initial;  // empty frame_id: the camera frame
    initial.pose = to_pose_msg(config_.initial_pose);
    pending_pose_ = initial;
  }

  pose_pub_ = private_nh.advertise<geometry_msgs::PoseStamped>("pose", 10);
  pose_covariance_pub_ =
      private_nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("pose_with_covariance", 10);
  status_pub_ = private_nh.advertise<TrackerStatus>("status", 10);
  marker_pub_ = private_nh.advertise<visualization_msgs::Marker>("marker", 1, /*latch=*/true);
  tf_broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>();
  tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
  // No spin thread: tf messages are handled on the nodelet's queue like everything else.
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh, false);
  private_image_transport_ = std::make_unique<image_transport::ImageTransport>(private_nh);
  debug_image_pub_ = private_image_transport_->advertise("debug_image", 1);

  // Diagnostics: ~pose rate and stamp age, and the tracking state.
  diagnostics_ = std::make_unique<diagnostic_updater::Updater>(nh, private_nh, getName());
  diagnostics_->setHardwareID(config_.object_frame);
  diagnostic_min_rate_hz_ = interface_.diagnostic_min_rate_hz;
  diagnostic_max_rate_hz_ = interface_.diagnostic_max_rate_hz;
  pose_diagnostic_ = std::make_unique<diagnostic_updater::TopicDiagnostic>(
      "pose", *diagnostics_,
      diagnostic_updater::FrequencyStatusParam(&diagnostic_min_rate_hz_, &diagnostic_max_rate_hz_,
                                               0.1, 10),
      diagnostic_updater::TimeStampStatusParam(-1.0, interface_.diagnostic_max_latency_s));
  diagnostics_->add("tracking", this, &TrackerNodelet::diagnose);
  diagnostic_timer_ = nh.createTimer(ros::Duration(1.0), [this](const ros::TimerEvent&) {
    try {
      diagnostics_->update();
    } catch (const std::exception& e) {
      NODELET_ERROR_THROTTLE(5.0, "diagnostics update failed: %s", e.what());
    }
  });

  // dynamic_reconfigure: start from the loaded parameters, not the .cfg defaults.
  reconfigure_server_ =
      std::make_unique<dynamic_reconfigure::Server<TrackerConfig>>(reconfigure_mutex_, private_nh);
  reconfigure_server_->updateConfig(reconfigure_values());
  reconfigure_server_->setCallback([this](TrackerConfig& config, uint32_t level) {
    try {
      on_reconfigure(config, level);
    } catch (const std::exception& e) {  // nothing leaves a callback
      NODELET_ERROR("reconfigure failed: %s", e.what());
      try {
        config = reconfigure_values();
      } catch (const std::exception&) {
      }
    }
  });

  initial_pose_sub_ =
      private_nh.subscribe("initial_pose", 1, &TrackerNodelet::on_initial_pose, this);
  init_srv_ = private_nh.advertiseService("init", &TrackerNodelet::on_init, this);
  reset_srv_ = private_nh.advertiseService("reset", &TrackerNodelet::on_reset, this);

  // Image and camera_info are subscribed separately (see on_image()): an exact-time
  // synchronizer (image_transport's CameraSubscriber) stalled for good after one lone
  // camera_info with a future stamp.
  image_transport_ = std::make_unique<image_transport::ImageTransport>(nh);
  image_sub_ = image_transport_->subscribe(
      "image", static_cast<std::uint32_t>(config_.queue_size), &TrackerNodelet::on_image, this,
      image_transport::TransportHints(config_.image_transport, ros::TransportHints(), private_nh));
  const std::string info_topic = image_transport::getCameraInfoTopic(image_sub_.getTopic());
  camera_info_sub_ = nh.subscribe(info_topic, 10, &TrackerNodelet::on_camera_info, this);
  waiting_timer_ = nh.createWallTimer(
      ros::WallDuration(std::max(0.01, interface_.camera_info_wait_s / 2.0)),
      [this](const ros::WallTimerEvent&) {
        if (waiting_image_ &&
            (ros::WallTime::now() - waiting_since_).toSec() >= interface_.camera_info_wait_s)
          flush_waiting_image();
      });
  NODELET_INFO("waiting for images on %s and %s%s", image_sub_.getTopic().c_str(),
               info_topic.c_str(),
               interface_.has_initial_pose ? "" : "; no ~initial_pose parameter: waiting for a pose on ~initial_pose or ~init");
}

// ---- Camera and frames ----------------------------------------------------------------------

bool TrackerNodelet::update_camera(const sensor_msgs::CameraInfo& info, std::string& error) {
  if (session_->has_camera() && same_camera(info, camera_info_)) return true;
  kct::PinholeCamera camera;
  try {
    camera = camera_from_info(info, config_.input_is_rectified);
  } catch (const std::invalid_argument& e) {
    error = e.what();
    return false;
  }
  if (!session_->has_camera()) {
    session_->set_camera(camera);
    NODELET_INFO("tracker started: camera %dx%d, fx %.1f fy %.1f cx %.1f cy %.1f%s",
                 camera.width(), camera.height(), camera.fx(), camera.fy(), camera.cx(),
                 camera.cy(), camera.has_distortion() ? ", undistorting" : "");
  } else {
    session_->set_camera(camera);
    NODELET_INFO("camera_info changed: camera %dx%d, fx %.1f fy %.1f cx %.1f cy %.1f",
                 camera.width(), camera.height(), camera.fx(), camera.fy(), camera.cx(),
                 camera.cy());
  }
  debug_map_x_.release();
  debug_map_y_.release();
  camera_info_ = info;
  return true;
}

void TrackerNodelet::warn_skipped(const std::string& reason) {
  const ros::WallTime now = ros::WallTime::now();
  if (reason == last_skip_reason_ && (now - last_skip_log_).toSec() < 5.0) return;
  NODELET_WARN("skipping frame: %s", reason.c_str());
  last_skip_reason_ = reason;
  last_skip_log_ = now;
}

void TrackerNodelet::on_camera_info(const sensor_msgs::CameraInfoConstPtr& info) {
  try {
    camera_infos_.push_back(info);
    while (camera_infos_.size() > 8) camera_infos_.pop_front();
    if (waiting_image_ && waiting_image_->header.stamp == info->header.stamp) {
      const sensor_msgs::ImageConstPtr image = waiting_image_;
      waiting_image_.reset();
      process_image(image, info);
    }
  } catch (const std::exception& e) {
    NODELET_ERROR_THROTTLE(5.0, "camera_info callback failed: %s", e.what());
  }
}

sensor_msgs::CameraInfoConstPtr TrackerNodelet::camera_info_for(const ros::Time& stamp) const {
  for (auto it = camera_infos_.rbegin(); it != camera_infos_.rend(); ++it)
    if ((*it)->header.stamp == stamp) return *it;
  return nullptr;
}

void TrackerNodelet::flush_waiting_image() {
  if (!waiting_image_) return;
  const sensor_msgs::ImageConstPtr image = waiting_image_;
  waiting_image_.reset();
  sensor_msgs::CameraInfoConstPtr info;
  if (!camera_infos_.empty()) {
    info = camera_infos_.back();
    ++frames_with_other_camera_info_;
  }
  process_image(image, info);
}

void TrackerNodelet::on_image(const sensor_msgs::ImageConstPtr& image) {
  try {
    const std::uint64_t dropped =
        drops_.update(image->header.seq, image->header.stamp.toSec());
    if (dropped > 0)
      NODELET_WARN_THROTTLE(5.0, "%llu frame(s) lost before the tracker (header.seq / stamp "
                                 "gap; %llu in total): the tracker is slower than the camera or "
                                 "the queue (~queue_size) is short",
                            static_cast<unsigned long long>(dropped),
                            static_cast<unsigned long long>(drops_.total()));
    last_dropped_ = dropped;
    flush_waiting_image();  // an older image is never held behind a newer one
    if (const sensor_msgs::CameraInfoConstPtr info = camera_info_for(image->header.stamp)) {
      process_image(image, info);
    } else {
      waiting_image_ = image;
      waiting_since_ = ros::WallTime::now();
      if (interface_.camera_info_wait_s <= 0.0) flush_waiting_image();
    }
  } catch (const std::exception& e) {
    NODELET_ERROR_THROTTLE(5.0, "image callback failed: %s", e.what());
  }
}

void TrackerNodelet::process_image(const sensor_msgs::ImageConstPtr& image,
                                   const sensor_msgs::CameraInfoConstPtr& info) {
  const auto start = std::chrono::steady_clock::now();
  // A status goes out for every image, also a skipped one (rosbag play --rate-control-topic
  // paces a bag on it, so a missing status would stall the player).
  auto status = boost::make_shared<TrackerStatus>();
  try {
    status->header = image->header;
    status->state = kct::to_string(kct::TrackStatus::kInvalidInput);
    status->dropped_frames = static_cast<std::uint32_t>(std::min<std::uint64_t>(last_dropped_, 0xffffffffu));
    status->dropped_frames_total = drops_.total();
    last_dropped_ = 0;
    auto skip = [&](const std::string& reason) {
      warn_skipped(reason);
      status->message = reason;
    };
    std::string camera_error;
    // Bounded work: the size is checked before any pixel is touched (a 20000x20000 frame would
    // cost gigabytes in the conversion alone).
    const std::string size_error =
        kct::implausible_image_size(image->width, image->height,
                                    static_cast<std::uint64_t>(config_.params.max_image_pixels));
    if (image->header.stamp.sec > kLastStampSec) {
      // tf listeners (ours included) add their cache time to a stamp: past the end of ROS 1 time
      // (2^32 s, year 2106) that throws inside tf2 and aborts the process.
      skip("image stamp " + std::to_string(image->header.stamp.sec) + "." +
           std::to_string(image->header.stamp.nsec) + " s is after 2100-01-01 (" +
           std::to_string(kLastStampSec) + " s): tf consumers would overflow ROS time");
    } else if (!info) {
      ++frames_without_camera_info_;
      skip("no camera_info received yet on " + camera_info_sub_.getTopic());
    } else if (!size_error.empty()) {
      skip(size_error);
    } else if (!update_camera(*info, camera_error)) {
      skip("unusable camera_info: " + camera_error);
    } else if (static_cast<int>(image->width) != session_->tracker().camera().width() ||
               static_cast<int>(image->height) != session_->tracker().camera().height()) {
      skip("image is " + std::to_string(image->width) + "x" + std::to_string(image->height) +
           " but camera_info says " + std::to_string(session_->tracker().camera().width()) + "x" +
           std::to_string(session_->tracker().camera().height()));
    } else {
      track(image, *status);
    }
  } catch (const std::exception& e) {
    // Nothing may escape a subscriber callback: it would take the whole manager down.
    NODELET_ERROR_THROTTLE(5.0, "frame %.3f failed: %s", image->header.stamp.toSec(), e.what());
    status->message = kct::truncate_for_message(e.what(), 512);
  }
  try {
    status->tracking_state = kct::to_string(session_->state());
    status->energy_level = session_->monitor().energy_level();
    status->bad_frames = session_->monitor().consecutive_bad_frames();
    status->frame_time_ms = kct::elapsed_ms(start);
    status_pub_.publish(status);
    last_status_ = *status;
    // In double seconds: ros::Time's operator- throws for stamps 2^31 s from now.
    last_latency_s_ = ros::Time::now().toSec() - image->header.stamp.toSec();
    ++frames_;
    diagnostics_->update();
    NODELET_DEBUG("frame %.3f: %s / %s, quality %.2f, %d inliers, %.1f ms",
                  image->header.stamp.toSec(), status->state.c_str(),
                  status->tracking_state.c_str(), status->quality, status->klt_inliers,
                  status->frame_time_ms);
  } catch (const std::exception& e) {
    NODELET_ERROR_THROTTLE(5.0, "publishing the status of frame %.3f failed: %s",
                           image->header.stamp.toSec(), e.what());
  }
}

void TrackerNodelet::track(const sensor_msgs::ImageConstPtr& image, TrackerStatus& status) {
  kct::Frame frame;
  try {
    frame.image = image_for_tracker(image);
  } catch (const std::exception& e) {
    warn_skipped(e.what());
    status.message = e.what();
    return;
  }
  frame.stamp_s = image->header.stamp.toSec();

  // A looping bag: the old tf data are stale (the session restarts the track itself).
  if (session_->time_jumps_back(frame.stamp_s)) tf_buffer_->clear();
  camera_frame_ = image->header.frame_id;
  if (!marker_published_) publish_marker(image->header.stamp);

  if (pending_pose_) {
    const geometry_msgs::PoseStamped given = *pending_pose_;
    pending_pose_.reset();
    try {
      const kct::Pose pose = to_camera_frame(given, image->header.frame_id, image->header.stamp);
      session_->initialize(pose);
      // The parameter pose stays the restart pose; one given at run time replaces it only when
      // there is none (a looping bag restarts where the operator started it).
      if (!session_->restart_pose()) session_->set_restart_pose(pose);
      NODELET_INFO("tracking from the given pose (frame '%s' -> '%s')",
                   given.header.frame_id.c_str(), image->header.frame_id.c_str());
    } catch (const std::exception& e) {
      NODELET_ERROR("given initial pose not used: %s", e.what());
    }
  }

  const kct::SessionResult session = session_->track(frame);
  const kct::TrackResult& result = session.frame;
  if (session.time_jumped_back)
    NODELET_INFO("image stamp jumped back to %.3f s (bag loop?)%s", frame.stamp_s,
                 session.restarted ? ": re-initialized to the initial pose" : "");
  if (session.state_changed() && !session.restarted) {
    if (session.state == kct::TrackState::kLost)
      NODELET_WARN("track LOST after %d bad frames (quality %.2f < %.2f): re-acquiring",
                   session_->monitor().consecutive_bad_frames(), session.quality,
                   session_->quality_params().min_quality);
    else
      NODELET_INFO("tracking state: %s -> %s", kct::to_string(session.previous_state),
                   kct::to_string(session.state));
  }

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
  status.quality = session.quality;
  status.good = session.good;

  if (result.status == kct::TrackStatus::kInvalidInput) {
    warn_skipped(result.message);
    return;
  }
  if (result.status == kct::TrackStatus::kExtrapolated) {
    NODELET_WARN_THROTTLE(5.0, "keypoint tracking failed (%d tracked, %d inliers): pose "
                               "extrapolated before refinement",
                          result.keypoints.tracked, result.keypoints.inliers);
  }
  const bool publish = session.has_pose() &&
                       (session.state != kct::TrackState::kLost || interface_.publish_when_lost);
  if (publish) publish_pose(image->header, result);
  status.pose_published = publish;
  if (debug_image_pub_.getNumSubscribers() > 0)
    publish_debug_image(image, frame.image, result, publish);
}

// ---- Initialization and reset ---------------------------------------------------------------

kct::Pose TrackerNodelet::to_camera_frame(const geometry_msgs::PoseStamped& pose,
                                          const std::string& camera_frame,
                                          const ros::Time& stamp) const {
  const kct::Pose given = from_pose_msg(pose.pose);  // throws for NaN / zero quaternion
  kct::Pose object_to_camera = given;
  if (!pose.header.frame_id.empty() && pose.header.frame_id != camera_frame) {
    geometry_msgs::TransformStamped frame_to_camera;
    const std::string& frame = pose.header.frame_id;
    try {
      // The pose's frame is held fixed between the pose's stamp and the image's.
      frame_to_camera = tf_buffer_->lookupTransform(camera_frame, stamp, frame, pose.header.stamp,
                                                    frame);
    } catch (const tf2::TransformException&) {
      try {
        frame_to_camera = tf_buffer_->lookupTransform(camera_frame, frame, ros::Time(0));
      } catch (const tf2::TransformException& e) {
        throw std::runtime_error("no tf from '" + frame + "' to the camera frame '" +
                                 camera_frame + "': " + e.what());
      }
    }
    object_to_camera = from_transform_msg(frame_to_camera.transform) * given;
  }
  if (!(object_to_camera.translation().z() > 0.0))
    throw std::runtime_error("the pose puts the object behind the camera (z = " +
                             std::to_string(object_to_camera.translation().z()) +
                             " m in the optical frame)");
  return object_to_camera;
}

bool TrackerNodelet::queue_pose(const geometry_msgs::PoseStamped& pose, std::string& message) {
  try {
    const geometry_msgs::Pose& p = pose.pose;
    const double norm = std::sqrt(p.orientation.x * p.orientation.x + p.orientation.y * p.orientation.y +
                                  p.orientation.z * p.orientation.z + p.orientation.w * p.orientation.w);
    from_pose_msg(p);
    if (std::abs(norm - 1.0) > 1e-2)
      throw std::invalid_argument("the orientation is not a unit quaternion (norm " +
                                  std::to_string(norm) + ")");
    // Check now what can be checked: the frame of the images is known after the first one.
    const bool camera_known = !camera_frame_.empty();
    if (camera_known || pose.header.frame_id.empty()) {
      geometry_msgs::PoseStamped latest = pose;
      latest.header.stamp = ros::Time(0);
      const kct::Pose object_to_camera = to_camera_frame(latest, camera_frame_, ros::Time(0));
      if (session_->has_camera()) {
        const std::string implausible =
            kct::implausible_pose(object_to_camera, *mesh_, session_->tracker().camera());
        if (!implausible.empty()) throw std::invalid_argument(implausible);
      }
    }
    pending_pose_ = pose;
    message = "accepted: tracking starts from it on the next image";
    if (!camera_known && !pose.header.frame_id.empty())
      message += " (no image yet: tf to the camera frame is checked then)";
    return true;
  } catch (const std::exception& e) {
    message = std::string("rejected: ") + e.what();
    return false;
  }
}

void TrackerNodelet::on_initial_pose(const geometry_msgs::PoseStampedConstPtr& pose) {
  std::string message;
  if (queue_pose(*pose, message))
    NODELET_INFO("~initial_pose %s", message.c_str());
  else
    NODELET_ERROR("~initial_pose %s", message.c_str());
}

bool TrackerNodelet::on_init(Init::Request& request, Init::Response& response) {
  response.accepted = queue_pose(request.pose, response.message);
  if (response.accepted)
    NODELET_INFO("~init %s", response.message.c_str());
  else
    NODELET_ERROR("~init %s", response.message.c_str());
  return true;
}

bool TrackerNodelet::on_reset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  session_->reset();
  pending_pose_.reset();
  response.success = true;
  response.message = "track dropped: waiting for a pose on ~initial_pose or ~init";
  NODELET_INFO("~reset: %s", response.message.c_str());
  return true;
}

// ---- Outputs --------------------------------------------------------------------------------

void TrackerNodelet::publish_pose(const std_msgs::Header& header, const kct::TrackResult& result) {
  auto pose = boost::make_shared<geometry_msgs::PoseStamped>();
  pose->header = header;
  pose->pose = to_pose_msg(result.object_to_camera);
  pose_pub_.publish(pose);
  pose_diagnostic_->tick(header.stamp);

  // Covariance (REP 103 order x y z rx ry rz, camera optical frame): from the KLT inliers'
  // residuals at the final pose, else the search box (scaled while re-acquiring).
  std::optional<kct::Matrix6d> covariance;
  const kct::KeypointInliers& inliers = result.keypoints.inlier_points;
  if (result.keypoints.success)
    covariance = kct::keypoint_pose_covariance(inliers.points_object, inliers.points_image,
                                               session_->tracker().camera(), result.object_to_camera);
  if (!covariance) {
    const double scale = result.status == kct::TrackStatus::kReacquired
                             ? std::pow(session_->quality_params().reacquire_search_scale, 2)
                             : 1.0;
    covariance = kct::search_box_pose_covariance(session_->tracker().diameter_m(),
                                                 session_->params(), scale);
  }
  auto with_covariance = boost::make_shared<geometry_msgs::PoseWithCovarianceStamped>();
  with_covariance->header = header;
  with_covariance->pose.pose = pose->pose;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) with_covariance->pose.covariance[6 * r + c] = (*covariance)(r, c);
  pose_covariance_pub_.publish(with_covariance);

  geometry_msgs::TransformStamped transform;
  transform.header = header;
  transform.child_frame_id = config_.object_frame;
  transform.transform = to_transform_msg(result.object_to_camera);
  tf_broadcaster_->sendTransform(transform);
}

void TrackerNodelet::publish_marker(const ros::Time& stamp) {
  marker_published_ = true;
  visualization_msgs::Marker marker;
  marker.header.stamp = stamp;
  marker.header.frame_id = config_.object_frame;
  marker.ns = getName();
  marker.id = 0;
  marker.action = visualization_msgs::Marker::ADD;
  marker.frame_locked = true;
  marker.pose.orientation.w = 1.0;
  marker.color.r = 0.2f;
  marker.color.g = 0.8f;
  marker.color.b = 0.2f;
  marker.color.a = 0.6f;
  const std::string url = rviz_mesh_url(config_);
  if (!url.empty()) {
    marker.type = visualization_msgs::Marker::MESH_RESOURCE;
    marker.mesh_resource = url;
    marker.mesh_use_embedded_materials = true;
    marker.scale.x = marker.scale.y = marker.scale.z = config_.mesh_scale;
  } else {
    marker.type = visualization_msgs::Marker::TRIANGLE_LIST;
    marker.scale.x = marker.scale.y = marker.scale.z = 1.0;
    marker.points.reserve(3 * mesh_->faces.size());
    for (const auto& face : mesh_->faces) {
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d& v = mesh_->vertices[face[k]];
        geometry_msgs::Point p;
        p.x = v.x();
        p.y = v.y();
        p.z = v.z();
        marker.points.push_back(p);
      }
    }
  }
  marker_pub_.publish(marker);
}

void TrackerNodelet::publish_debug_image(const sensor_msgs::ImageConstPtr& image,
                                         const cv::Mat& frame, const kct::TrackResult& result,
                                         bool published) {
  const kct::PinholeCamera& camera = session_->tracker().camera();
  cv::Mat input = frame;
  if (camera.has_distortion()) {
    // Drawn on the undistorted frame the tracker works on (ideal pinhole).
    if (debug_map_x_.empty()) camera.undistortion_maps(debug_map_x_, debug_map_y_);
    cv::remap(frame, input, debug_map_x_, debug_map_y_, cv::INTER_LINEAR);
  }
  const std::string label = std::string(kct::to_string(session_->state())) +
                            cv::format(" q %.2f", session_->monitor().last_quality()) +
                            (published ? "" : " (not published)");
  cv_bridge::CvImage out(image->header, "bgr8",
                         kct::draw_tracking_overlay(input, result, camera, *mesh_,
                                                    session_->tracker().diameter_m(),
                                                    session_->tracker().contour_extractor(), label));
  debug_image_pub_.publish(out.toImageMsg());
}

void TrackerNodelet::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  const kct::TrackState state = session_->state();
  if (!session_->has_camera())
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no usable image + camera_info yet");
  else if (state == kct::TrackState::kLost)
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "track lost: re-acquiring");
  else if (state == kct::TrackState::kWaitingForPose)
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "waiting for a pose (~initial_pose, ~init)");
  else
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "tracking");
  status.add("state", kct::to_string(state));
  status.add("last frame", last_status_.state);
  status.add("quality", session_->monitor().last_quality());
  status.add("consecutive bad frames", session_->monitor().consecutive_bad_frames());
  status.add("KLT inliers / tracked",
             std::to_string(last_status_.klt_inliers) + " / " + std::to_string(last_status_.klt_tracked));
  status.add("frame time (ms)", last_status_.frame_time_ms);
  status.add("latency at publication (s)", last_latency_s_);
  status.add("frames", frames_);
  status.add("frames lost before the tracker (header.seq / stamp gaps)", drops_.total());
  status.add("images skipped: no camera_info yet", frames_without_camera_info_);
  status.add("images paired with a camera_info of another stamp", frames_with_other_camera_info_);
}

// ---- dynamic_reconfigure --------------------------------------------------------------------

TrackerConfig TrackerNodelet::reconfigure_values() const {
  const kct::TrackerParams& p = session_ ? session_->params() : config_.params;
  TrackerConfig c;
  c.preset = config_.preset;
  c.refine = p.refine;
  c.blur_sigma_px = p.blur_sigma_px;
  c.final_hops = p.final_hops;
  c.min_hops_cap = p.min_hops_cap;
  c.max_hops_without_improvement_cap = p.max_hops_without_improvement_cap;
  c.max_hops_cap = p.max_hops_cap;
  c.max_reprojection_increase_px = p.max_reprojection_increase_px;
  c.max_keypoints = p.max_keypoints;
  c.klt_window_px = p.klt_window_px;
  c.klt_pyramid_levels = p.klt_pyramid_levels;
  c.klt_forward_backward_px = p.klt_forward_backward_px;
  c.ransac_reprojection_px = p.ransac_reprojection_px;
  c.klt_min_inlier_ratio = p.klt_min_inlier_ratio;
  const kct::TrackQualityParams& q = session_ ? session_->quality_params() : interface_.quality;
  c.min_quality = q.min_quality;
  c.lost_after_bad_frames = q.lost_after_bad_frames;
  c.recover_after_good_frames = q.recover_after_good_frames;
  c.publish_when_lost = interface_.publish_when_lost;
  return c;
}

void TrackerNodelet::on_reconfigure(TrackerConfig& config, uint32_t /*level*/) {
  kct::TrackerParams params = session_->params();
  if (config.preset != config_.preset) {
    kct::TrackerParams preset;
    try {
      preset = kct::make_preset(config.preset);
    } catch (const std::invalid_argument& e) {
      NODELET_WARN("reconfigure: %s; keeping preset '%s'", e.what(), config_.preset.c_str());
      config = reconfigure_values();
      return;
    }
    // What needs a rebuild of the visibility table or contours stays as configured.
    preset.icosphere_subdivisions = params.icosphere_subdivisions;
    preset.visibility_resolution_px = params.visibility_resolution_px;
    preset.visibility_cache_dir = params.visibility_cache_dir;
    preset.sharp_edge_angle_deg = params.sharp_edge_angle_deg;
    preset.contour_sample_spacing_px = params.contour_sample_spacing_px;
    preset.random_seed = params.random_seed;
    params = preset;
    config_.preset = config.preset;
    NODELET_INFO("reconfigure: preset '%s' loaded", config.preset.c_str());
  } else {
    params.refine = config.refine;
    params.blur_sigma_px = config.blur_sigma_px;
    params.final_hops = config.final_hops;
    params.min_hops_cap = config.min_hops_cap;
    params.max_hops_without_improvement_cap = config.max_hops_without_improvement_cap;
    params.max_hops_cap = config.max_hops_cap;
    params.max_reprojection_increase_px = config.max_reprojection_increase_px;
    params.max_keypoints = config.max_keypoints;
    params.klt_window_px = config.klt_window_px;
    params.klt_pyramid_levels = config.klt_pyramid_levels;
    params.klt_forward_backward_px = config.klt_forward_backward_px;
    params.ransac_reprojection_px = config.ransac_reprojection_px;
    params.klt_min_inlier_ratio = config.klt_min_inlier_ratio;
  }
  kct::TrackQualityParams quality = session_->quality_params();
  quality.min_quality = config.min_quality;
  quality.lost_after_bad_frames = config.lost_after_bad_frames;
  quality.recover_after_good_frames = config.recover_after_good_frames;
  try {
    params.validate();
    quality.validate();
  } catch (const std::invalid_argument& e) {
    NODELET_WARN("reconfigure rejected: %s", e.what());
    config = reconfigure_values();
    return;
  }
  config_.params = params;
  session_->set_params(params);
  session_->set_quality_params(quality);
  interface_.quality = quality;
  interface_.publish_when_lost = config.publish_when_lost;
  // Pushed back to the server: a preset's values, or the values as applied.
  config = reconfigure_values();
}

}  // namespace klt_contour_tracker

PLUGINLIB_EXPORT_CLASS(klt_contour_tracker::TrackerNodelet, nodelet::Nodelet)
