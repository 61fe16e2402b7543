#include "klt_contour_tracker/ros/interface_config.h"

#include <xmlrpcpp/XmlRpcValue.h>

#include <cmath>
#include <sstream>

#include "klt_contour_tracker/ros/param_loader.h"

namespace klt_contour_tracker {
namespace {

[[noreturn]] void fail(const std::string& name, const std::string& reason) {
  throw ConfigError("~" + name + ": " + reason);
}

void read(const ros::NodeHandle& nh, const std::string& name, double& out) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(name, v)) return;
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) out = static_cast<double>(v);
  else if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) out = static_cast<int>(v);
  else fail(name, "must be a number");
}

void read(const ros::NodeHandle& nh, const std::string& name, int& out) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(name, v)) return;
  if (v.getType() != XmlRpc::XmlRpcValue::TypeInt) fail(name, "must be an integer");
  out = static_cast<int>(v);
}

void read(const ros::NodeHandle& nh, const std::string& name, bool& out) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(name, v)) return;
  if (v.getType() != XmlRpc::XmlRpcValue::TypeBoolean) fail(name, "must be a boolean");
  out = static_cast<bool>(v);
}

}  // namespace

std::vector<std::string> interface_parameter_names() {
  return {"publish_when_lost",      "energy_weight",        "min_quality",
          "energy_level_smoothing", "lost_after_bad_frames", "recover_after_good_frames",
          "reacquire_search_scale", "diagnostic_min_rate",  "diagnostic_max_rate",
          "diagnostic_max_latency", "diagnostic_period",   "camera_info_wait_s"};
}

InterfaceConfig load_interface_config(const ros::NodeHandle& nh) {
  InterfaceConfig c;
  c.has_initial_pose = nh.hasParam("initial_pose/position") || nh.hasParam("initial_pose/orientation");
  read(nh, "publish_when_lost", c.publish_when_lost);
  read(nh, "energy_weight", c.quality.energy_weight);
  read(nh, "min_quality", c.quality.min_quality);
  read(nh, "energy_level_smoothing", c.quality.energy_level_smoothing);
  read(nh, "lost_after_bad_frames", c.quality.lost_after_bad_frames);
  read(nh, "recover_after_good_frames", c.quality.recover_after_good_frames);
  read(nh, "reacquire_search_scale", c.quality.reacquire_search_scale);
  try {
    c.quality.validate();
  } catch (const std::invalid_argument& e) {
    std::string what = e.what();
    const std::string prefix = "TrackQualityParams.";
    if (what.rfind(prefix, 0) == 0) what = "~" + what.substr(prefix.size());
    throw ConfigError(what);
  }
  read(nh, "diagnostic_min_rate", c.diagnostic_min_rate_hz);
  read(nh, "diagnostic_max_rate", c.diagnostic_max_rate_hz);
  read(nh, "diagnostic_max_latency", c.diagnostic_max_latency_s);
  if (!(c.diagnostic_min_rate_hz >= 0.0) || !std::isfinite(c.diagnostic_min_rate_hz))
    fail("diagnostic_min_rate", "must be a finite number >= 0 Hz");
  if (!(c.diagnostic_max_rate_hz > c.diagnostic_min_rate_hz))
    fail("diagnostic_max_rate", "must be greater than ~diagnostic_min_rate");
  if (!(c.diagnostic_max_latency_s > 0.0))
    fail("diagnostic_max_latency", "must be > 0 s");
  read(nh, "camera_info_wait_s", c.camera_info_wait_s);
  if (!(c.camera_info_wait_s >= 0.0 && c.camera_info_wait_s <= 10.0))
    fail("camera_info_wait_s", "must be in [0, 10] s");
  return c;
}

std::string describe(const InterfaceConfig& c) {
  std::ostringstream s;
  s << "  initial pose: " << (c.has_initial_pose ? "from ~initial_pose/*" : "waiting for ~initial_pose or ~init") << "\n"
    << "  publish_when_lost: " << (c.publish_when_lost ? "true" : "false") << "\n"
    << "  energy_weight: " << c.quality.energy_weight << "\n"
    << "  min_quality: " << c.quality.min_quality << "\n"
    << "  energy_level_smoothing: " << c.quality.energy_level_smoothing << "\n"
    << "  lost_after_bad_frames: " << c.quality.lost_after_bad_frames << "\n"
    << "  recover_after_good_frames: " << c.quality.recover_after_good_frames << "\n"
    << "  reacquire_search_scale: " << c.quality.reacquire_search_scale << "\n"
    << "  diagnostic_min_rate: " << c.diagnostic_min_rate_hz << "  # Hz\n"
    << "  diagnostic_max_rate: " << c.diagnostic_max_rate_hz << "  # Hz\n"
    << "  diagnostic_max_latency: " << c.diagnostic_max_latency_s << "  # s\n"
    << "  camera_info_wait_s: " << c.camera_info_wait_s << "  # s\n";
  return s.str();
}

}  // namespace klt_contour_tracker
