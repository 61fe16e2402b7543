#pragma once
/// \file tracker_nodelet.h
/// ROS wrapper of kct::TrackingSession. Subscribes `image` (image_transport) and `camera_info`
/// (a plain subscription: the latest camera_infos are cached, see on_image()) and
/// `~initial_pose`; serves `~init` and `~reset`; publishes `~pose`, `~pose_with_covariance`
/// (object_to_camera in the image's optical frame, header = the image's header), `~status`,
/// `~debug_image`, `~marker`, the tf image frame -> ~object_frame and /diagnostics. The session
/// (the same core code as track_sequence and the benchmark) runs the pipeline, the
/// WAITING_FOR_POSE / TRACKING / LOST state machine, re-acquisition while LOST and the restart on
/// a backward time jump; the nodelet converts messages and publishes. Poses in and out are
/// metres (REP 103), whatever ~mesh_scale.
/// All work is done in callbacks on the nodelet's single-threaded callback queue.

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/publisher.h>
#include <dynamic_reconfigure/server.h>
#include <geometry_msgs/PoseStamped.h>
#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <boost/thread/recursive_mutex.hpp>
#include <deque>
#include <memory>
#include <optional>

#include "klt_contour_tracker/Init.h"
#include "klt_contour_tracker/TrackerConfig.h"
#include "klt_contour_tracker/TrackerStatus.h"
#include "klt_contour_tracker/core/contour_extractor.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/track_quality.h"
#include "klt_contour_tracker/core/tracker.h"
#include "klt_contour_tracker/core/tracking_session.h"
#include "klt_contour_tracker/ros/frame_drop_counter.h"
#include "klt_contour_tracker/ros/interface_config.h"
#include "klt_contour_tracker/ros/param_loader.h"

namespace klt_contour_tracker {

/// Nodelet `klt_contour_tracker/TrackerNodelet`; parameters in config/tracker.yaml.
class TrackerNodelet : public nodelet::Nodelet {
 public:
  TrackerNodelet();
  ~TrackerNodelet() override;

 private:
  /// Reads the configuration and loads the model; on any error logs NODELET_FATAL and does not
  /// subscribe (the manager and its other nodelets keep running).
  void onInit() override;
  /// An image arrives. Pairing without an exact-time synchronizer (one lone or mis-stamped
  /// message must never stop later ones): the image is processed at once with the cached
  /// camera_info of the same stamp when there is one; otherwise it waits (one image at most)
  /// for that camera_info until the next image arrives or ~camera_info_wait_s passes, and is
  /// then processed with the latest camera_info received. Also counts frames dropped before it.
  void on_image(const sensor_msgs::ImageConstPtr& image);
  /// A camera_info arrives: cached (the last few); releases a waiting image of the same stamp.
  void on_camera_info(const sensor_msgs::CameraInfoConstPtr& info);
  /// Processes the waiting image, if any, with the latest camera_info.
  void flush_waiting_image();
  /// The cached camera_info with `stamp`, null when there is none.
  sensor_msgs::CameraInfoConstPtr camera_info_for(const ros::Time& stamp) const;
  /// One frame: camera update, conversion, tracking, publishing; a ~status for every image,
  /// whatever happens (no exception leaves this function). `info` may be null (none yet).
  void process_image(const sensor_msgs::ImageConstPtr& image,
                     const sensor_msgs::CameraInfoConstPtr& info);
  /// Creates the session's tracker on the first usable camera_info and updates its camera when it
  /// changes. Returns false with the reason in `error` when the camera_info is unusable.
  bool update_camera(const sensor_msgs::CameraInfo& info, std::string& error);
  /// Tracks one image whose size matches the camera; fills `status`, publishes the outputs.
  void track(const sensor_msgs::ImageConstPtr& image, TrackerStatus& status);

  /// ~initial_pose: a PoseStamped in any frame, applied on the next image.
  void on_initial_pose(const geometry_msgs::PoseStampedConstPtr& pose);
  /// ~init: same as ~initial_pose, replying whether the pose is acceptable.
  bool on_init(Init::Request& request, Init::Response& response);
  /// ~reset: drops the track; waits for a pose.
  bool on_reset(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  /// Checks a given pose (finite, unit quaternion, tf to the camera frame when known, in front
  /// of the camera) and queues it for the next image. Returns false with the reason.
  bool queue_pose(const geometry_msgs::PoseStamped& pose, std::string& message);
  /// The pose in the camera optical frame `camera_frame` at `stamp` (the pose's frame held
  /// fixed; latest tf when `stamp` is not available). Throws std::runtime_error.
  kct::Pose to_camera_frame(const geometry_msgs::PoseStamped& pose, const std::string& camera_frame,
                            const ros::Time& stamp) const;
  /// dynamic_reconfigure: a changed preset loads the preset's values into `config` (pushed back
  /// to the server); other changes are validated and applied, or reverted with a warning.
  void on_reconfigure(TrackerConfig& config, uint32_t level);
  /// The reconfigurable values of the current parameters.
  TrackerConfig reconfigure_values() const;

  void publish_pose(const std_msgs::Header& header, const kct::TrackResult& result);
  void publish_debug_image(const sensor_msgs::ImageConstPtr& image, const cv::Mat& frame,
                           const kct::TrackResult& result, bool published);
  /// Latched ~marker (the mesh in ~object_frame), once, stamped with the first image's stamp.
  void publish_marker(const ros::Time& stamp);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  NodeletConfig config_;
  InterfaceConfig interface_;
  std::shared_ptr<const kct::Mesh> mesh_;
  /// Pipeline, quality monitor, re-acquisition, restart pose (~initial_pose parameter, or the
  /// first pose given at run time); created in onInit once the model is loaded.
  std::unique_ptr<kct::TrackingSession> session_;
  sensor_msgs::CameraInfo camera_info_;  ///< the camera the tracker currently uses
  cv::Mat debug_map_x_, debug_map_y_;    ///< undistortion of the debug image (raw input)
  /// Logs a skipped frame's reason: at once when the reason changes, else at most every 5 s
  /// (a throttle per call site would hide a new kind of bad input behind the previous one).
  void warn_skipped(const std::string& reason);
  std::string last_skip_reason_;
  ros::WallTime last_skip_log_;
  std::string camera_frame_;  ///< frame_id of the last image
  std::optional<geometry_msgs::PoseStamped> pending_pose_;  ///< applied on the next image
  bool marker_published_ = false;
  // Statistics for diagnostics.
  TrackerStatus last_status_;
  double last_latency_s_ = 0.0;
  std::size_t frames_ = 0;
  std::uint64_t last_dropped_ = 0;  ///< frames lost right before the image being processed

  std::unique_ptr<image_transport::ImageTransport> image_transport_;
  std::unique_ptr<image_transport::ImageTransport> private_image_transport_;
  image_transport::Subscriber image_sub_;
  ros::Subscriber camera_info_sub_;
  std::deque<sensor_msgs::CameraInfoConstPtr> camera_infos_;  ///< latest last, at most 8
  sensor_msgs::ImageConstPtr waiting_image_;  ///< waits for its camera_info (see on_image())
  ros::WallTime waiting_since_;
  ros::WallTimer waiting_timer_;
  FrameDropCounter drops_;  ///< frames lost before the tracker
  std::size_t frames_without_camera_info_ = 0;  ///< images skipped: no camera_info yet
  std::size_t frames_with_other_camera_info_ = 0;  ///< images paired with a differently stamped one
  image_transport::Publisher debug_image_pub_;
  ros::Subscriber initial_pose_sub_;
  ros::ServiceServer init_srv_, reset_srv_;
  ros::Publisher pose_pub_, pose_covariance_pub_, status_pub_, marker_pub_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_broadcaster_;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;

  boost::recursive_mutex reconfigure_mutex_;
  std::unique_ptr<dynamic_reconfigure::Server<TrackerConfig>> reconfigure_server_;
  std::unique_ptr<diagnostic_updater::Updater> diagnostics_;
  std::unique_ptr<diagnostic_updater::TopicDiagnostic> pose_diagnostic_;
  double diagnostic_min_rate_hz_ = 1.0, diagnostic_max_rate_hz_ = 1000.0;
  ros::Timer diagnostic_timer_;
};

}  // namespace klt_contour_tracker
