#pragma once
/// \file interface_config.h
/// Parameters of the nodelet's ROS interface that are not tracker tunables: the track-quality
/// state machine, publishing while lost, diagnostics. Read from the private node handle next to
/// load_config() (param_loader.h); see config/tracker.yaml for every name, default and unit.

#include <ros/node_handle.h>

#include <string>
#include <vector>

#include "klt_contour_tracker/core/track_quality.h"

namespace klt_contour_tracker {

/// The interface part of the configuration.
struct InterfaceConfig {
  /// ~initial_pose/position or ~initial_pose/orientation is set: track from the first image;
  /// otherwise wait for ~initial_pose (topic) or ~init (service).
  bool has_initial_pose = false;
  /// ~publish_when_lost: also publish ~pose, ~pose_with_covariance and tf while LOST.
  bool publish_when_lost = false;
  /// ~energy_weight, ~min_quality, ~energy_level_smoothing, ~lost_after_bad_frames,
  /// ~recover_after_good_frames, ~reacquire_search_scale.
  kct::TrackQualityParams quality;
  /// ~diagnostic_min_rate, ~diagnostic_max_rate: expected ~pose rate window, Hz.
  double diagnostic_min_rate_hz = 1.0;
  double diagnostic_max_rate_hz = 1000.0;
  /// ~diagnostic_max_latency: ~pose stamp age at publication above which diagnostics warn, s.
  double diagnostic_max_latency_s = 1.0;
  /// ~camera_info_wait_s: how long an image without a camera_info of its own stamp waits for
  /// one before it is processed with the latest camera_info received, s (0 = never waits).
  double camera_info_wait_s = 0.1;
};

/// Reads and validates the interface parameters. Throws ConfigError ("~name: reason").
InterfaceConfig load_interface_config(const ros::NodeHandle& private_nh);

/// The private parameter names read by load_interface_config() (without "~").
std::vector<std::string> interface_parameter_names();

/// Multi-line "name: value" listing, for the start-up echo.
std::string describe(const InterfaceConfig& config);

}  // namespace klt_contour_tracker
