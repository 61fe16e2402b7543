#pragma once
/// \file tracker_nodelet.h
/// ROS wrapper of kct::Tracker. Subscribes `image` + `camera_info` (image_transport camera
/// subscriber, resolved in the nodelet's namespace), publishes `~pose` (object_to_camera in the
/// image's optical frame, header = the image's header), `~status` and the tf image frame ->
/// ~object_frame. All work is done in the subscriber callback on the nodelet's callback queue.

#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/transform_broadcaster.h>

#include <memory>

#include "klt_contour_tracker/TrackerStatus.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/tracker.h"
#include "klt_contour_tracker/ros/param_loader.h"

namespace klt_contour_tracker {

/// Nodelet `klt_contour_tracker/TrackerNodelet`; parameters in config/tracker.yaml.
class TrackerNodelet : public nodelet::Nodelet {
 public:
  TrackerNodelet();
  ~TrackerNodelet() override;

 private:
  /// Reads the configuration and loads the mesh; on any error logs NODELET_FATAL and does not
  /// subscribe (the manager and its other nodelets keep running).
  void onInit() override;
  /// One frame: camera update, conversion, Tracker::track(), publishing.
  void on_image(const sensor_msgs::ImageConstPtr& image,
                const sensor_msgs::CameraInfoConstPtr& info);
  /// Creates the tracker on the first camera_info and updates its camera when it changes.
  /// Returns false (and logs) when the camera_info is unusable.
  bool update_camera(const sensor_msgs::CameraInfo& info);
  /// Converts and tracks one image whose size matches the camera; publishes pose and tf, fills
  /// `status`.
  void track(const sensor_msgs::ImageConstPtr& image, TrackerStatus& status);

  NodeletConfig config_;
  std::shared_ptr<const kct::Mesh> mesh_;
  std::unique_ptr<kct::Tracker> tracker_;
  sensor_msgs::CameraInfo camera_info_;  ///< the camera the tracker currently uses
  ros::Time last_stamp_;
  std::unique_ptr<image_transport::ImageTransport> image_transport_;
  image_transport::CameraSubscriber camera_sub_;
  ros::Publisher pose_pub_;
  ros::Publisher status_pub_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_broadcaster_;
};

}  // namespace klt_contour_tracker
