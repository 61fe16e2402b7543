#include "klt_contour_tracker/ros/param_loader.h"

#include "klt_contour_tracker/core/model_units.h"

#include <ros/names.h>
#include <ros/param.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iomanip>
#include <set>
#include <sstream>

namespace klt_contour_tracker {
namespace {

const char* const kNodeParams[] = {"model_description", "object_link", "input_is_rectified",
                                   "mesh_resource", "mesh_scale", "initial_pose/position",
                                   "initial_pose/orientation", "object_frame", "preset",
                                   "queue_size", "image_transport"};

const char* type_name(XmlRpc::XmlRpcValue::Type type) {
  switch (type) {
    case XmlRpc::XmlRpcValue::TypeBoolean: return "a boolean";
    case XmlRpc::XmlRpcValue::TypeInt: return "an integer";
    case XmlRpc::XmlRpcValue::TypeDouble: return "a number";
    case XmlRpc::XmlRpcValue::TypeString: return "a string";
    case XmlRpc::XmlRpcValue::TypeArray: return "a list";
    case XmlRpc::XmlRpcValue::TypeStruct: return "a dictionary";
    default: return "of another type";
  }
}

[[noreturn]] void fail(const std::string& name, const std::string& reason) {
  throw ConfigError("~" + name + ": " + reason);
}

void wrong_type(const std::string& name, const char* expected, const XmlRpc::XmlRpcValue& v) {
  fail(name, std::string("must be ") + expected + ", got " +
                 type_name(const_cast<XmlRpc::XmlRpcValue&>(v).getType()));
}

// Overloads by field type. Each returns false (value untouched) when the parameter is not set.
bool read(const ros::NodeHandle& nh, const std::string& name, double& out) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(name, v)) return false;
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) out = static_cast<double>(v);
  else if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) out = static_cast<int>(v);
  else wrong_type(name, "a number", v);
  return true;
}

bool read(const ros::NodeHandle& nh, const std::string& name, int& out) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(name, v)) return false;
  if (v.getType() != XmlRpc::XmlRpcValue::TypeInt) wrong_type(name, "an integer", v);
  out = static_cast<int>(v);
  return true;
}

bool read(const ros::NodeHandle& nh, const std::string& name, bool& out) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(name, v)) return false;
  if (v.getType() != XmlRpc::XmlRpcValue::TypeBoolean) wrong_type(name, "a boolean", v);
  out = static_cast<bool>(v);
  return true;
}

bool read(const ros::NodeHandle& nh, const std::string& name, std::string& out) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(name, v)) return false;
  if (v.getType() != XmlRpc::XmlRpcValue::TypeString) wrong_type(name, "a string", v);
  out = static_cast<std::string>(v);
  return true;
}

/// Reads ~<name> for the kct::TrackerParams field of that name (kct::set_param parses and
/// type-checks it). Returns false when the parameter is not set.
bool read_tracker_field(const ros::NodeHandle& nh, const std::string& name, kct::TrackerParams& out) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(name, v)) return false;
  std::string text;
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean: text = static_cast<bool>(v) ? "true" : "false"; break;
    case XmlRpc::XmlRpcValue::TypeInt: text = std::to_string(static_cast<int>(v)); break;
    case XmlRpc::XmlRpcValue::TypeDouble: {
      std::ostringstream number;
      number << std::setprecision(17) << static_cast<double>(v);
      text = number.str();
      break;
    }
    case XmlRpc::XmlRpcValue::TypeString: text = static_cast<std::string>(v); break;
    default: wrong_type(name, "a boolean, a number or a string", v);
  }
  try {
    kct::set_param(out, name, text);
  } catch (const std::invalid_argument& e) {
    // set_param says "TrackerParams.<name>: <reason>"; fail() names the ROS parameter.
    std::string reason = e.what();
    const std::string prefix = "TrackerParams." + name + ": ";
    if (reason.rfind(prefix, 0) == 0) reason = reason.substr(prefix.size());
    fail(name, reason);
  }
  return true;
}

std::vector<double> read_vector(const ros::NodeHandle& nh, const std::string& name,
                                std::size_t size) {
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(name, v)) fail(name, "is required (a list of " + std::to_string(size) + " numbers)");
  if (v.getType() != XmlRpc::XmlRpcValue::TypeArray || static_cast<std::size_t>(v.size()) != size)
    fail(name, "must be a list of " + std::to_string(size) + " numbers");
  std::vector<double> out(size);
  for (std::size_t i = 0; i < size; ++i) {
    XmlRpc::XmlRpcValue& e = v[static_cast<int>(i)];
    if (e.getType() == XmlRpc::XmlRpcValue::TypeDouble) out[i] = static_cast<double>(e);
    else if (e.getType() == XmlRpc::XmlRpcValue::TypeInt) out[i] = static_cast<int>(e);
    else fail(name, "entry " + std::to_string(i) + " is not a number");
    if (!std::isfinite(out[i])) fail(name, "entry " + std::to_string(i) + " is not finite");
  }
  return out;
}

kct::Pose read_initial_pose(const ros::NodeHandle& nh) {
  const std::vector<double> p = read_vector(nh, "initial_pose/position", 3);
  const std::vector<double> q = read_vector(nh, "initial_pose/orientation", 4);
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (std::abs(norm - 1.0) > 1e-2)
    fail("initial_pose/orientation",
         "must be a unit quaternion x y z w (norm " + std::to_string(norm) + ")");
  if (p[2] <= 0.0)
    fail("initial_pose/position",
         "z = " + std::to_string(p[2]) +
             " m puts the object behind the camera (object_to_camera, optical frame: z forward)");
  return kct::pose_from_quaternion(p[0], p[1], p[2], q[0], q[1], q[2], q[3]);
}

/// $ROS_HOME, else ~/.ros (where roslaunch keeps its logs).
std::string ros_home() {
  if (const char* home = std::getenv("ROS_HOME"); home && *home) return home;
  const char* user_home = std::getenv("HOME");
  return std::string(user_home && *user_home ? user_home : "/tmp") + "/.ros";
}

std::string format(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}
std::string format(bool v) { return v ? "true" : "false"; }
std::string format(const std::string& v) { return "'" + v + "'"; }

}  // namespace

NodeletConfig load_config(const ros::NodeHandle& nh) {
  NodeletConfig config;
  read(nh, "model_description", config.model_description);
  read(nh, "object_link", config.object_link);
  read(nh, "mesh_resource", config.mesh_resource);
  if (!config.model_description.empty()) {
    // The URDF wins over ~mesh_resource (which the launch files always set).
    if (config.object_link.empty())
      fail("object_link", "is required with ~model_description (the URDF link to track)");
  } else if (config.mesh_resource.empty()) {
    fail("mesh_resource",
         "is required (package://, file:// or a path to a mesh file) unless "
         "~model_description and ~object_link give the model");
  }
  read(nh, "mesh_scale", config.mesh_scale);
  // Only the mesh is in model units: ~initial_pose and every published pose are metres (REP 103).
  try {
    kct::ModelUnits units(config.mesh_scale);  // the core's range for a model scale
  } catch (const std::invalid_argument&) {
    fail("mesh_scale", "is " + format(config.mesh_scale) + "; allowed: [" +
                           format(kct::ModelUnits::kMinScale) + ", " +
                           format(kct::ModelUnits::kMaxScale) +
                           "] metres per model unit (0.001 for millimetres)");
  }
  // Optional: without it the nodelet waits for ~initial_pose (topic) or ~init (service).
  if (nh.hasParam("initial_pose/position") || nh.hasParam("initial_pose/orientation"))
    config.initial_pose = read_initial_pose(nh);
  read(nh, "object_frame", config.object_frame);
  if (config.object_frame.empty()) fail("object_frame", "must not be empty");
  read(nh, "queue_size", config.queue_size);
  if (config.queue_size < 1)
    fail("queue_size", "must be >= 1, got " + std::to_string(config.queue_size));
  read(nh, "image_transport", config.image_transport);
  read(nh, "input_is_rectified", config.input_is_rectified);

  read(nh, "preset", config.preset);
  try {
    config.params = kct::make_preset(config.preset);
  } catch (const std::invalid_argument& e) {
    fail("preset", e.what());
  }
  for (const auto& field : kct::describe(config.params))
    read_tracker_field(nh, field.first, config.params);
  // A second start with the same model loads the visibility table from here (seconds saved).
  if (!nh.hasParam("visibility_cache_dir"))
    config.params.visibility_cache_dir = ros_home() + "/klt_contour_tracker/visibility";
  try {
    config.params.validate();
  } catch (const std::invalid_argument& e) {
    // validate() says "TrackerParams.<field> ..."; name the ROS parameter instead.
    std::string what = e.what();
    const std::string prefix = "TrackerParams.";
    if (what.rfind(prefix, 0) == 0) what = "~" + what.substr(prefix.size());
    throw ConfigError(what);
  }
  return config;
}

std::vector<std::string> unknown_parameters(const ros::NodeHandle& nh) {
  std::set<std::string> known(std::begin(kNodeParams), std::end(kNodeParams));
  for (const auto& field : kct::describe(kct::TrackerParams{})) known.insert(field.first);
  std::vector<std::string> all;
  std::vector<std::string> unknown;
  if (!ros::param::getParamNames(all)) return unknown;
  const std::string prefix = nh.getNamespace() + "/";
  for (const std::string& name : all) {
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string relative = name.substr(prefix.size());
    if (!known.count(relative)) unknown.push_back("~" + relative);
  }
  return unknown;
}

std::string describe(const NodeletConfig& c) {
  std::ostringstream s;
  const Eigen::Quaterniond q(c.initial_pose.rotation());
  const Eigen::Vector3d t = c.initial_pose.translation();
  if (!c.model_description.empty())
    s << "  model_description: <URDF, " << c.model_description.size() << " characters>\n"
      << "  object_link: " << format(c.object_link) << "\n";
  else
    s << "  mesh_resource: " << format(c.mesh_resource) << "\n"
      << "  mesh_scale: " << c.mesh_scale << "\n";
  s << "  input_is_rectified: " << format(c.input_is_rectified) << "\n"
    << "  initial_pose/position: [" << t.x() << ", " << t.y() << ", " << t.z() << "]  # m\n"
    << "  initial_pose/orientation: [" << q.x() << ", " << q.y() << ", " << q.z() << ", "
    << q.w() << "]  # x y z w\n"
    << "  object_frame: " << format(c.object_frame) << "\n"
    << "  queue_size: " << c.queue_size << "\n"
    << "  image_transport: " << format(c.image_transport) << "\n"
    << "  preset: " << format(c.preset) << "\n";
  for (const auto& [name, value] : kct::describe(c.params)) s << "  " << name << ": " << value << "\n";
  std::string out = s.str();
  if (!out.empty()) out.pop_back();
  return out;
}

}  // namespace klt_contour_tracker
