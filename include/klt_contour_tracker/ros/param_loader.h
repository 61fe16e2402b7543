#pragma once
/// \file param_loader.h
/// Every ROS parameter of the tracker nodelet, read in one place from the private node handle,
/// validated, and printable for the start-up echo. The tracker's tunables start from the preset
/// `~preset`; any `~<TrackerParams field name>` overrides the preset's value.

#include <ros/node_handle.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/tracker_params.h"

namespace klt_contour_tracker {

/// Invalid configuration; what() starts with the parameter's name ("~mesh_scale: ...").
class ConfigError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The nodelet's configuration (see config/tracker.yaml for every parameter and its unit).
struct NodeletConfig {
  std::string model_description;  ///< ~model_description: URDF XML; when set it gives the model
  std::string object_link;        ///< ~object_link: the URDF link tracked (frame = object frame)
  std::string mesh_resource;      ///< ~mesh_resource: package://, file:// or a plain path (no URDF)
  double mesh_scale = 1.0;        ///< ~mesh_scale: model units -> metres (~mesh_resource only)
  bool input_is_rectified = true;  ///< ~input_is_rectified: true: P, no distortion; false: K and D
  /// ~initial_pose/position + orientation: object_to_camera, metres; optional (identity when
  /// unset: interface_config.h's has_initial_pose says whether it was given).
  kct::Pose initial_pose = kct::Pose::Identity();
  std::string object_frame = "object";  ///< ~object_frame: child frame of the published tf
  std::string preset = "realtime";     ///< ~preset: kct::make_preset() name
  int queue_size = 1;                  ///< ~queue_size: image/camera_info subscriber queue
  std::string image_transport = "raw";  ///< ~image_transport: image_transport plugin name
  kct::TrackerParams params;           ///< preset + ~<field> overrides, validated
};

/// Reads and validates every parameter. Throws ConfigError naming the parameter and the reason
/// (missing required value, wrong type, out of range, non-finite pose, object behind the camera).
NodeletConfig load_config(const ros::NodeHandle& private_nh);

/// Private parameters that no part of the nodelet reads (typos), as "~name".
std::vector<std::string> unknown_parameters(const ros::NodeHandle& private_nh);

/// Multi-line "name: value" listing of the whole configuration, for the start-up echo.
std::string describe(const NodeletConfig& config);

}  // namespace klt_contour_tracker
