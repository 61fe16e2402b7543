#pragma once
// Helpers for the rostests that drive a TrackerNodelet with frames rendered here by the core
// renderer (the demo crate over a smooth random background): load the nodelet into /manager,
// publish one image + camera_info and wait for its ~status, record the outputs.
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <gtest/gtest.h>
#include <nodelet/NodeletLoad.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/image_encodings.h>

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "../core/synthetic_scene.h"
#include "ros_test_util.h"
#include "klt_contour_tracker/TrackerStatus.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/renderer.h"
#include "klt_contour_tracker/ros/ros_conversions.h"

namespace kct_test {

const std::string kCameraFrame = "camera_optical";
const std::string kMeshPath = KCT_SOURCE_DIR "/models/demo_crate.obj";

/// Stamps that only go forward across all tests of a process (a backward jump re-initializes).
inline ros::Time next_stamp() {
  static double t = 1000.0;
  t += 0.1;
  return ros::Time(t);
}

// Pose <-> message: the package's own conversions (ros_conversions.h).
using klt_contour_tracker::from_pose_msg;
using klt_contour_tracker::to_pose_msg;

/// The demo crate (or several objects) rendered over a background with a 640x480 camera.
struct Scene {
  kct::PinholeCamera camera{525.0, 525.0, 319.5, 239.5, 640, 480};
  std::shared_ptr<kct::Mesh> mesh = std::make_shared<kct::Mesh>(kct::load_mesh(kMeshPath));
  kct::Renderer renderer{mesh};
  cv::Mat background = kct::test::make_background(camera.size(), 11);

  /// The crate at each of `poses` (composited by depth), or the background alone.
  cv::Mat render(const std::vector<kct::Pose>& poses, int seed) const {
    cv::Mat frame = background.clone();
    cv::Mat depth(camera.size(), CV_32F, cv::Scalar(1e9));
    for (const kct::Pose& pose : poses) {
      const kct::RenderOutput out = renderer.render(pose, camera);
      const cv::Mat nearer = out.mask() & (out.depth < depth);
      out.color.copyTo(frame, nearer);
      out.depth.copyTo(depth, nearer);
    }
    cv::Mat noise(frame.size(), CV_16SC3);
    cv::RNG rng(seed);
    rng.fill(noise, cv::RNG::NORMAL, 0, 1.5);
    cv::Mat frame16;
    frame.convertTo(frame16, CV_16SC3);
    frame16 += noise;
    frame16.convertTo(frame, CV_8UC3);
    return frame;
  }

  sensor_msgs::CameraInfo info(const ros::Time& stamp) const {
    sensor_msgs::CameraInfo i;
    i.header.stamp = stamp;
    i.header.frame_id = kCameraFrame;
    i.width = camera.width();
    i.height = camera.height();
    i.distortion_model = "plumb_bob";
    i.D = {0, 0, 0, 0, 0};
    i.K = {camera.fx(), 0, camera.cx(), 0, camera.fy(), camera.cy(), 0, 0, 1};
    i.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    i.P = {camera.fx(), 0, camera.cx(), 0, 0, camera.fy(), camera.cy(), 0, 0, 0, 1, 0};
    return i;
  }
};

inline sensor_msgs::ImagePtr image_msg(const cv::Mat& bgr, const ros::Time& stamp) {
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->header.stamp = stamp;
  msg->header.frame_id = kCameraFrame;
  msg->height = bgr.rows;
  msg->width = bgr.cols;
  msg->encoding = sensor_msgs::image_encodings::BGR8;
  msg->step = static_cast<uint32_t>(bgr.cols * 3);
  msg->data.assign(bgr.data, bgr.data + bgr.total() * 3);
  return msg;
}

/// One TrackerNodelet in /manager with its own camera topics, and its recorded outputs.
class Harness {
 public:
  /// Sets `params` (relative to the nodelet's private namespace) and loads the nodelet.
  Harness(const std::string& name, const std::map<std::string, XmlRpc::XmlRpcValue>& params)
      : name_("/" + name), nh_() {
    for (const auto& [key, value] : params) nh_.setParam(name_ + "/" + key, value);
    loaded_ = load_tracker_nodelet(name_, name_ + "_camera");
    pose_sub_ = nh_.subscribe(name_ + "/pose", 100, &Harness::on_pose, this);
    covariance_sub_ = nh_.subscribe(name_ + "/pose_with_covariance", 100, &Harness::on_covariance, this);
    status_sub_ = nh_.subscribe(name_ + "/status", 100, &Harness::on_status, this);
    image_pub_ = nh_.advertise<sensor_msgs::Image>(name_ + "_camera/image_raw", 1);
    info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>(name_ + "_camera/camera_info", 1);
    connected_ = wait_for(
        [&] {
          return image_pub_.getNumSubscribers() > 0 && info_pub_.getNumSubscribers() > 0 &&
                 pose_sub_.getNumPublishers() > 0 && status_sub_.getNumPublishers() > 0;
        },
        60.0);
  }
  bool ready() const { return loaded_ && connected_; }
  const std::string& name() const { return name_; }

  /// Publishes one image + camera_info and waits for its status, the one stamped as the image
  /// (and, when the status says a pose went out, for the pose). Null on timeout. Matched by
  /// stamp: a status still on its way for an image published alone before (publish_image())
  /// would otherwise be taken for this one's, and every later send() would read the status of
  /// the frame before it.
  klt_contour_tracker::TrackerStatus::ConstPtr send(const sensor_msgs::ImagePtr& image,
                                                   const sensor_msgs::CameraInfo& info,
                                                   double timeout_s = 120.0) {
    const size_t before = statuses().size();
    info_pub_.publish(info);
    image_pub_.publish(image);
    klt_contour_tracker::TrackerStatus::ConstPtr status;
    const auto arrived = [&] {
      const auto all = statuses();
      for (size_t i = before; i < all.size(); ++i)
        if (all[i]->header.stamp == image->header.stamp) {
          status = all[i];
          return true;
        }
      return false;
    };
    if (!wait_for(arrived, timeout_s)) return nullptr;
    if (status->pose_published)
      wait_for([&] { return last_pose() && last_pose()->header.stamp == status->header.stamp; }, 5.0);
    return status;
  }

  /// Publishes a camera_info alone (no image).
  void publish_info(const sensor_msgs::CameraInfo& info) { info_pub_.publish(info); }
  /// Publishes an image alone (its camera_info is expected from elsewhere or not at all).
  void publish_image(const sensor_msgs::ImagePtr& image) { image_pub_.publish(image); }

  std::vector<klt_contour_tracker::TrackerStatus::ConstPtr> statuses() {
    std::lock_guard<std::mutex> lock(mutex_);
    return statuses_;
  }
  std::vector<geometry_msgs::PoseStamped::ConstPtr> poses() {
    std::lock_guard<std::mutex> lock(mutex_);
    return poses_;
  }
  geometry_msgs::PoseStamped::ConstPtr last_pose() {
    std::lock_guard<std::mutex> lock(mutex_);
    return poses_.empty() ? nullptr : poses_.back();
  }
  std::vector<geometry_msgs::PoseWithCovarianceStamped::ConstPtr> covariances() {
    std::lock_guard<std::mutex> lock(mutex_);
    return covariances_;
  }

 private:
  void on_pose(const geometry_msgs::PoseStamped::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    poses_.push_back(m);
  }
  void on_covariance(const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    covariances_.push_back(m);
  }
  void on_status(const klt_contour_tracker::TrackerStatus::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    statuses_.push_back(m);
  }

  std::string name_;
  ros::NodeHandle nh_;
  bool loaded_ = false, connected_ = false;
  ros::Subscriber pose_sub_, covariance_sub_, status_sub_;
  ros::Publisher image_pub_, info_pub_;
  std::mutex mutex_;
  std::vector<klt_contour_tracker::TrackerStatus::ConstPtr> statuses_;
  std::vector<geometry_msgs::PoseStamped::ConstPtr> poses_;
  std::vector<geometry_msgs::PoseWithCovarianceStamped::ConstPtr> covariances_;
};

/// XmlRpc list of doubles.
inline XmlRpc::XmlRpcValue list(const std::vector<double>& values) {
  XmlRpc::XmlRpcValue v;
  v.setSize(static_cast<int>(values.size()));
  for (size_t i = 0; i < values.size(); ++i) v[static_cast<int>(i)] = values[i];
  return v;
}

/// ~initial_pose/position and /orientation parameters for `pose`.
inline void set_initial_pose(std::map<std::string, XmlRpc::XmlRpcValue>& params, const kct::Pose& pose) {
  const geometry_msgs::Pose m = to_pose_msg(pose);
  params["initial_pose/position"] = list({m.position.x, m.position.y, m.position.z});
  params["initial_pose/orientation"] =
      list({m.orientation.x, m.orientation.y, m.orientation.z, m.orientation.w});
}

/// A crate pose in front of the camera: 0.45 m away, turned so that three faces show.
inline kct::Pose crate_pose(double x = 0.0, double y = 0.0, double z = 0.45) {
  kct::Pose pose = kct::test::make_pose(z, 115, -30, 15);
  pose.translation() = Eigen::Vector3d(x, y, z);
  return pose;
}

}  // namespace kct_test
