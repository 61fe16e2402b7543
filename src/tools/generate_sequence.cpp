/// \file generate_sequence.cpp
/// Renders a synthetic tracking sequence with exact ground truth: the model over a real
/// photograph, along a smooth seeded 6-DoF trajectory (OPT-style motion groups), with sensor
/// noise, optional motion blur and lighting changes. Writes a sequence folder (000000.png...,
/// K.txt, pose.txt; see sequence_io.h) and optionally a rosbag. Needs no ROS master.
///
/// The options after "hard conditions" in the usage (the benchmark's hard section) switch to a
/// scene render: a hand-held trajectory, the photograph on a wall behind the object receiving
/// cast shadows (shadow map), distractor objects of the object's own appearance, a moving
/// occluder, Blinn-Phong highlights, lighting changes, motion blur over the shutter time,
/// defocus and JPEG compression; they also write visible.txt (the fraction of the object's
/// silhouette that is inside the image and not occluded, per frame). Without them the output
/// is byte-identical to what it was before they existed.

#include <rosbag/bag.h>
#include <geometry_msgs/PoseStamped.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <optional>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/model_units.h"
#include "klt_contour_tracker/core/renderer.h"
#include "klt_contour_tracker/core/sequence_io.h"
#include "klt_contour_tracker/core/shadow_map.h"
#include "klt_contour_tracker/core/trajectory.h"

namespace {

constexpr const char* kDefaultBackground = "/usr/share/doc/opencv-doc/examples/data/graf1.png";
constexpr const char* kFrameId = "camera_optical_frame";
constexpr double kFirstStamp_s = 1000.0;

const char* kUsage =
    "usage: generate_sequence --model MESH --output-dir DIR [options]\n"
    "  --model-scale S          metres per model unit (0.001 for millimetres) [1]: the mesh is\n"
    "                           read and pose.txt written in model units (track_sequence reads\n"
    "                           them back with the same --model-scale); the bag is metres (REP 103)\n"
    "  --bag FILE.bag           also write /camera/image_raw, /camera/camera_info,\n"
    "                           /ground_truth/pose at 30 Hz stamps from t = 1000 s\n"
    "  --frames N               number of frames [150]\n"
    "  --width W --height H     image size, px [640 480]\n"
    "  --fx F --fy F --cx C --cy C  intrinsics, px [fx = fy = 525, centre of the image]\n"
    "  --motion M               free|xy|z|inplane|outofplane|flash|movinglight [free]\n"
    "  --speed 1..5             motion speed [3]\n"
    "  --seed N                 trajectory, texture-free noise and background seed [1]\n"
    "  --distance-min M --distance-max M  object centre distance range, m [0.35 0.6]\n"
    "  --noise-sigma S          Gaussian sensor noise, grey levels [2]\n"
    "  --motion-blur-samples N  sub-frame renders averaged over one frame interval [1]\n"
    "  --background PATH        background photograph [opencv-doc's graf1.png]\n"
    " hard conditions (benchmark's hard section; any of them switches to the scene render):\n"
    "  --trajectory opt|handheld  OPT-style --motion groups, or hand-held motion [opt]\n"
    "  --max-translation-mm T --max-rotation-deg R  hand-held limits per frame [30 8]\n"
    "  --typical-translation-mm T --typical-rotation-deg R  steady hand-held speed, per axis\n"
    "                           and frame (standard deviation) [8 2]\n"
    "  --jerk-probability P     hand-held jerks (sudden direction changes) per frame [0.07]\n"
    "  --leave-start N --leave-frames M  the object leaves the image at frame N for M frames\n"
    "  --distractors N          objects of the object's own appearance next to it (copies of\n"
    "                           the mesh, boxes and cylinders in its mean colour) [0]\n"
    "  --occluder-passes N      a moving occluder crosses the object N times [0]\n"
    "  --specular S --shininess E  Blinn-Phong highlight [0 32]\n"
    "  --smooth-shading         interpolated vertex normals\n"
    "  --shadows                cast shadows (object, distractors, occluder; onto each other\n"
    "                           and onto the wall carrying the photograph)\n"
    "  --lighting-changes       a moving light, gain steps and flashes\n"
    "  --shutter-fraction F     exposure time / frame interval for the motion blur [1]\n"
    "  --defocus-px R           defocus: disc blur of radius R px [0]\n"
    "  --jpeg-quality Q         write JPEG frames of quality Q (1-100) instead of PNG [0 = PNG]\n";

struct Options {
  std::string model, output_dir, bag, background = kDefaultBackground;
  double model_scale = 1.0;
  int frames = 150, width = 640, height = 480;
  double fx = 525.0, fy = -1.0, cx = -1.0, cy = -1.0;
  kct::TrajectoryParams trajectory;
  double noise_sigma = 2.0;
  int blur_samples = 1;
  // Hard conditions (see the usage). The scene render is used when any is set.
  bool handheld = false;
  kct::HandheldParams hand;
  int distractors = 0, occluder_passes = 0;
  double specular = 0.0, shininess = 32.0;
  bool smooth_shading = false, shadows = false, lighting_changes = false;
  double shutter_fraction = 1.0, defocus_px = 0.0;
  int jpeg_quality = 0;
  bool scene() const {
    return handheld || distractors > 0 || occluder_passes > 0 || specular > 0.0 ||
           smooth_shading || shadows || lighting_changes;
  }
};

Options parse(int argc, char** argv) {
  Options o;
  bool fy_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << kUsage;
      std::exit(0);
    }
    if (arg == "--smooth-shading" || arg == "--shadows" || arg == "--lighting-changes") {
      (arg == "--shadows" ? o.shadows : arg == "--smooth-shading" ? o.smooth_shading
                                                                   : o.lighting_changes) = true;
      continue;
    }
    if (i + 1 >= argc) throw std::invalid_argument("missing value after " + arg);
    const std::string value = argv[++i];
    if (arg == "--model") o.model = value;
    else if (arg == "--model-scale") o.model_scale = std::stod(value);
    else if (arg == "--output-dir") o.output_dir = value;
    else if (arg == "--bag") o.bag = value;
    else if (arg == "--frames") o.frames = std::stoi(value);
    else if (arg == "--width") o.width = std::stoi(value);
    else if (arg == "--height") o.height = std::stoi(value);
    else if (arg == "--fx") o.fx = std::stod(value);
    else if (arg == "--fy") o.fy = std::stod(value), fy_given = true;
    else if (arg == "--cx") o.cx = std::stod(value);
    else if (arg == "--cy") o.cy = std::stod(value);
    else if (arg == "--motion") o.trajectory.motion = kct::motion_group_from_string(value);
    else if (arg == "--speed") o.trajectory.speed = std::stoi(value);
    else if (arg == "--seed") o.trajectory.seed = std::stoull(value);
    else if (arg == "--distance-min") o.trajectory.distance_min_m = std::stod(value);
    else if (arg == "--distance-max") o.trajectory.distance_max_m = std::stod(value);
    else if (arg == "--noise-sigma") o.noise_sigma = std::stod(value);
    else if (arg == "--motion-blur-samples") o.blur_samples = std::stoi(value);
    else if (arg == "--background") o.background = value;
    else if (arg == "--trajectory") {
      if (value != "opt" && value != "handheld")
        throw std::invalid_argument("--trajectory must be opt or handheld, got '" + value + "'");
      o.handheld = value == "handheld";
    } else if (arg == "--max-translation-mm") o.hand.max_translation_m = 1e-3 * std::stod(value);
    else if (arg == "--max-rotation-deg") o.hand.max_rotation_deg = std::stod(value);
    else if (arg == "--typical-translation-mm") o.hand.typical_translation_m = 1e-3 * std::stod(value);
    else if (arg == "--typical-rotation-deg") o.hand.typical_rotation_deg = std::stod(value);
    else if (arg == "--jerk-probability") o.hand.jerk_probability = std::stod(value);
    else if (arg == "--leave-start") o.hand.leave_start_frame = std::stoi(value);
    else if (arg == "--leave-frames") o.hand.leave_frames = std::stoi(value);
    else if (arg == "--distractors") o.distractors = std::stoi(value);
    else if (arg == "--occluder-passes") o.occluder_passes = std::stoi(value);
    else if (arg == "--specular") o.specular = std::stod(value);
    else if (arg == "--shininess") o.shininess = std::stod(value);
    else if (arg == "--shutter-fraction") o.shutter_fraction = std::stod(value);
    else if (arg == "--defocus-px") o.defocus_px = std::stod(value);
    else if (arg == "--jpeg-quality") o.jpeg_quality = std::stoi(value);
    else throw std::invalid_argument("unknown option " + arg);
  }
  if (o.distractors < 0 || o.distractors > 8)
    throw std::invalid_argument("--distractors must be in [0, 8]");
  if (o.occluder_passes < 0 || o.occluder_passes > 10)
    throw std::invalid_argument("--occluder-passes must be in [0, 10]");
  if (!(o.specular >= 0.0) || !(o.shininess > 0.0))
    throw std::invalid_argument("--specular must be >= 0 and --shininess > 0");
  if (!(o.shutter_fraction > 0.0 && o.shutter_fraction <= 1.0))
    throw std::invalid_argument("--shutter-fraction must be in (0, 1]");
  if (!(o.defocus_px >= 0.0 && o.defocus_px <= 50.0))
    throw std::invalid_argument("--defocus-px must be in [0, 50]");
  if (o.jpeg_quality < 0 || o.jpeg_quality > 100)
    throw std::invalid_argument("--jpeg-quality must be in [1, 100] (0 = PNG)");
  if (!(o.hand.max_translation_m > 0.0 && o.hand.max_rotation_deg > 0.0 &&
        o.hand.typical_translation_m >= 0.0 && o.hand.typical_rotation_deg >= 0.0 &&
        o.hand.jerk_probability >= 0.0 && o.hand.jerk_probability <= 1.0))
    throw std::invalid_argument("hand-held limits must be > 0, typical speeds >= 0 and "
                                "--jerk-probability in [0, 1]");
  if (o.hand.leave_frames < 0) throw std::invalid_argument("--leave-frames must be >= 0");

  if (o.model.empty() || o.output_dir.empty())
    throw std::invalid_argument("--model and --output-dir are required");
  if (o.frames < 1) throw std::invalid_argument("--frames must be >= 1");
  if (o.blur_samples < 1) throw std::invalid_argument("--motion-blur-samples must be >= 1");
  if (!(o.noise_sigma >= 0.0)) throw std::invalid_argument("--noise-sigma must be >= 0");
  if (!fy_given) o.fy = o.fx;
  if (o.cx < 0) o.cx = 0.5 * (o.width - 1);
  if (o.cy < 0) o.cy = 0.5 * (o.height - 1);
  return o;
}

/// The photograph scaled to cover the image and centre-cropped; a procedural clutter image
/// (with a warning) when it cannot be read.
cv::Mat make_background(const std::string& path, cv::Size size, uint64_t seed) {
  cv::Mat photo;
  if (std::filesystem::is_regular_file(path)) photo = cv::imread(path, cv::IMREAD_COLOR);
  if (!photo.empty()) {
    const double scale = std::max(double(size.width) / photo.cols, double(size.height) / photo.rows);
    cv::Mat scaled;
    cv::resize(photo, scaled,
               cv::Size(std::max(size.width, int(std::ceil(photo.cols * scale))),
                        std::max(size.height, int(std::ceil(photo.rows * scale)))),
               0, 0, scale < 1.0 ? cv::INTER_AREA : cv::INTER_LINEAR);
    const cv::Rect crop((scaled.cols - size.width) / 2, (scaled.rows - size.height) / 2,
                        size.width, size.height);
    return scaled(crop).clone();
  }
  std::cerr << "WARNING: cannot read background '" << path
            << "' (install the Debian package opencv-doc, or pass --background); "
               "using a procedural background\n";
  cv::RNG rng(seed + 99);
  cv::Mat background(size, CV_8UC3, cv::Scalar(110, 120, 125));
  for (int i = 0; i < 300; ++i) {
    const cv::Point p(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const cv::Point q = p + cv::Point(rng.uniform(-60, 60), rng.uniform(-60, 60));
    const cv::Scalar c(rng.uniform(40, 220), rng.uniform(40, 220), rng.uniform(40, 220));
    if (i % 3 == 0) cv::circle(background, p, rng.uniform(4, 30), c, cv::FILLED, cv::LINE_AA);
    else cv::rectangle(background, p, q, c, cv::FILLED);
  }
  cv::GaussianBlur(background, background, cv::Size(0, 0), 1.5);
  return background;
}

sensor_msgs::Image to_image_message(const cv::Mat& bgr, const std_msgs::Header& header) {
  sensor_msgs::Image msg;
  msg.header = header;
  msg.height = bgr.rows;
  msg.width = bgr.cols;
  msg.encoding = "bgr8";
  msg.is_bigendian = 0;
  msg.step = bgr.cols * 3;
  msg.data.resize(msg.step * bgr.rows);
  for (int r = 0; r < bgr.rows; ++r)
    std::memcpy(&msg.data[r * msg.step], bgr.ptr(r), msg.step);
  return msg;
}

sensor_msgs::CameraInfo to_camera_info(const kct::PinholeCamera& camera,
                                       const std_msgs::Header& header) {
  sensor_msgs::CameraInfo info;
  info.header = header;
  info.width = camera.width();
  info.height = camera.height();
  info.distortion_model = "plumb_bob";
  info.D.assign(5, 0.0);
  const cv::Matx33d K = camera.K();
  for (int i = 0; i < 9; ++i) info.K[i] = K.val[i];
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) info.P[4 * r + c] = K(r, c);
  return info;
}

geometry_msgs::PoseStamped to_pose_message(const kct::Pose& pose, const std_msgs::Header& header) {
  geometry_msgs::PoseStamped msg;
  msg.header = header;
  const Eigen::Quaterniond q(pose.linear());
  msg.pose.position.x = pose.translation().x();
  msg.pose.position.y = pose.translation().y();
  msg.pose.position.z = pose.translation().z();
  msg.pose.orientation.x = q.x();
  msg.pose.orientation.y = q.y();
  msg.pose.orientation.z = q.z();
  msg.pose.orientation.w = q.w();
  return msg;
}

// ---------------------------------------------------------------------------------------------
// Scene render (hard conditions)
// ---------------------------------------------------------------------------------------------

/// Closed axis-aligned box mesh centred at the origin (half extents in metres), one colour.
std::shared_ptr<const kct::Mesh> make_box(const Eigen::Vector3d& half, cv::Vec3b color) {
  auto mesh = std::make_shared<kct::Mesh>();
  for (int i = 0; i < 8; ++i)
    mesh->vertices.emplace_back((i & 1) ? half.x() : -half.x(), (i & 2) ? half.y() : -half.y(),
                                (i & 4) ? half.z() : -half.z());
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    mesh->faces.emplace_back(q[0], q[1], q[2]);
    mesh->faces.emplace_back(q[0], q[2], q[3]);
  }
  mesh->base_color = color;
  return mesh;
}

/// Closed cylinder along z centred at the origin, one colour.
std::shared_ptr<const kct::Mesh> make_cylinder(double radius, double height, int segments,
                                               cv::Vec3b color) {
  auto mesh = std::make_shared<kct::Mesh>();
  for (int ring = 0; ring < 2; ++ring)
    for (int k = 0; k < segments; ++k) {
      const double a = 2.0 * M_PI * k / segments;
      mesh->vertices.emplace_back(radius * std::cos(a), radius * std::sin(a),
                                  (ring - 0.5) * height);
    }
  const int bottom = static_cast<int>(mesh->vertices.size());
  mesh->vertices.emplace_back(0, 0, -0.5 * height);
  mesh->vertices.emplace_back(0, 0, 0.5 * height);
  for (int k = 0; k < segments; ++k) {
    const int n = (k + 1) % segments;
    mesh->faces.emplace_back(k, n, segments + n);
    mesh->faces.emplace_back(k, segments + n, segments + k);
    mesh->faces.emplace_back(bottom, n, k);
    mesh->faces.emplace_back(bottom + 1, segments + k, segments + n);
  }
  mesh->base_color = color;
  return mesh;
}

/// Mean albedo of a mesh: its texture's mean, else its base colour.
cv::Vec3b mean_color(const kct::Mesh& mesh) {
  if (!mesh.has_texture()) return mesh.base_color;
  const cv::Scalar m = cv::mean(mesh.texture);
  return cv::Vec3b(cv::saturate_cast<uchar>(m[0]), cv::saturate_cast<uchar>(m[1]),
                   cv::saturate_cast<uchar>(m[2]));
}

/// Rotation that stands an object (z up) on a table seen from `elevation_deg` above, turned
/// by `yaw` about its z axis.
Eigen::Matrix3d upright(double elevation_deg, double yaw) {
  const double tilt = elevation_deg * M_PI / 180.0;
  Eigen::Matrix3d canonical;
  canonical.col(0) = Eigen::Vector3d(1, 0, 0);
  canonical.col(1) = Eigen::Vector3d(0, -std::sin(tilt), std::cos(tilt));
  canonical.col(2) = Eigen::Vector3d(0, -std::cos(tilt), -std::sin(tilt));
  return canonical * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

/// The static part of a scene: distractors (camera frame), the occluder's mesh, the wall.
struct Scene {
  std::vector<kct::PlacedMesh> distractors;
  std::shared_ptr<const kct::Mesh> occluder;
  double occluder_radius_m = 0.0;
  double wall_depth_m = 1.0;     ///< the photograph hangs on the plane z = wall_depth_m
  double object_radius_m = 0.0;  ///< half the tracked object's diameter
  std::vector<std::pair<int, int>> occluder_windows;  ///< [first, last) frames of each pass
  cv::Mat occluder_directions;  ///< CV_64F, one image-plane sweep angle per pass
};

Scene make_scene(const Options& o, const kct::Mesh& object, double nominal_distance_m,
                 double distance_range_m, cv::RNG& rng) {
  Scene scene;
  const double diameter = object.diameter();
  scene.object_radius_m = 0.5 * diameter;
  const cv::Vec3b color = mean_color(object);
  const auto object_copy = std::make_shared<const kct::Mesh>(object);
  const double behind = nominal_distance_m + distance_range_m + 0.5 * diameter;
  double farthest = nominal_distance_m;
  for (int k = 0; k < o.distractors; ++k) {
    kct::PlacedMesh placed;
    double size = diameter;
    switch (k % 3) {
      case 0: placed.mesh = object_copy; break;
      case 1:
        size = diameter * rng.uniform(0.6, 1.0);
        placed.mesh = make_box(Eigen::Vector3d(0.35, 0.25, 0.3) * size, color);
        break;
      default:
        size = diameter * rng.uniform(0.6, 1.0);
        placed.mesh = make_cylinder(0.25 * size, 0.8 * size, 48, color);
    }
    // Around the nominal position, a little behind the object's range, close beside it.
    const double angle = 2.0 * M_PI * (k + rng.uniform(0.0, 0.6)) / o.distractors;
    const double depth = behind + 0.5 * size + rng.uniform(0.0, 0.05);
    const double lateral = depth * rng.uniform(0.35, 0.6) * diameter / nominal_distance_m;
    const Eigen::Vector3d center(lateral * std::cos(angle) * 1.3, lateral * std::sin(angle), depth);
    placed.object_to_camera.linear() = upright(rng.uniform(20.0, 50.0), rng.uniform(0.0, 2.0 * M_PI));
    placed.object_to_camera.translation() =
        center - placed.object_to_camera.linear() * placed.mesh->bounding_box_center();
    farthest = std::max(farthest, depth + 0.5 * size);
    scene.distractors.push_back(placed);
  }
  scene.wall_depth_m = farthest + 0.5 * diameter + 0.25;
  if (o.occluder_passes > 0) {
    // A forearm-sized, skin-coloured cylinder.
    scene.occluder_radius_m = 0.03;
    scene.occluder = make_cylinder(scene.occluder_radius_m, 0.3, 48, cv::Vec3b(120, 150, 200));
    const int span = std::max(1, o.frames / o.occluder_passes);
    scene.occluder_directions = cv::Mat(o.occluder_passes, 1, CV_64F);
    for (int p = 0; p < o.occluder_passes; ++p) {
      const int length = std::min(span, std::max(8, static_cast<int>(span * 0.7)));
      const int first = p * span + (span - length) / 2;
      scene.occluder_windows.emplace_back(first, first + length);
      scene.occluder_directions.at<double>(p) = rng.uniform(-0.6, 0.6) + (p % 2) * M_PI;
    }
  }
  return scene;
}

/// Pose of the occluder at `frame_time` (fractional frame index) when it is in a pass: like a
/// hand reaching in front of the object and back, it comes in from one side (in the image
/// plane, 3 cm in front of the object) until its edge reaches the object's centre (about half
/// of the object hidden) and withdraws.
std::optional<kct::Pose> occluder_pose(const Scene& scene, double frame_time,
                                       const Eigen::Vector3d& object_center_camera) {
  for (std::size_t p = 0; p < scene.occluder_windows.size(); ++p) {
    const auto [first, last] = scene.occluder_windows[p];
    if (frame_time < first || frame_time > last) continue;
    const double progress = (frame_time - first) / std::max(1, last - first);  // 0..1
    const double angle = scene.occluder_directions.at<double>(static_cast<int>(p));
    const Eigen::Vector3d across(std::cos(angle), std::sin(angle), 0.0);
    const Eigen::Vector3d along(-across.y(), across.x(), 0.0);
    const double depth = object_center_camera.z() - scene.object_radius_m - scene.occluder_radius_m - 0.03;
    const double scale = depth / object_center_camera.z();
    // Offset of the occluder's axis from the object's centre (seen from the camera), metres
    // at the object's distance: out of the object's way at the ends, one occluder radius at
    // the peak (its edge on the object's centre).
    const double reach = scene.object_radius_m + scene.occluder_radius_m + 0.02;
    const double offset = reach - (reach - scene.occluder_radius_m / scale) * std::sin(M_PI * progress);
    kct::Pose pose = kct::Pose::Identity();
    // Cylinder axis (z) along `along`, slightly tilted towards the camera.
    pose.linear() = Eigen::Quaterniond::FromTwoVectors(
                        Eigen::Vector3d::UnitZ(), (along + Eigen::Vector3d(0, 0, -0.15)).normalized())
                        .toRotationMatrix();
    pose.translation() = (object_center_camera + offset * across) * scale;
    return pose;
  }
  return std::nullopt;
}

/// Lighting of the scene render at fractional frame `frame_time`: a fixed lamp above-left
/// near the camera (cast shadows fall close beside the objects), or (--lighting-changes) a lamp circling above the object, gain steps every 15-30
/// frames (0.55-1.5) and single-frame flashes.
kct::RenderOptions scene_lighting(const Options& o, double frame_time,
                                  const std::vector<double>& gain_steps,
                                  const std::vector<int>& flash_frames) {
  kct::RenderOptions r;
  r.light_direction_camera = Eigen::Vector3d(0.3, -0.45, -0.85);
  r.ambient = 0.35;
  r.diffuse = 0.75;
  r.specular = o.specular;
  r.shininess = o.shininess;
  r.smooth_shading = o.smooth_shading;
  if (o.lighting_changes) {
    const double angle = 2.0 * M_PI * 0.12 * frame_time / o.trajectory.frame_rate_hz + 0.8;
    r.light_direction_camera = Eigen::Vector3d(0.85 * std::cos(angle), -0.6 + 0.3 * std::sin(angle), -0.45);
    r.ambient = 0.22;
    r.diffuse = 0.9;
    const int frame = static_cast<int>(std::floor(frame_time + 0.5));
    r.light_gain = gain_steps[std::clamp(frame / 20, 0, static_cast<int>(gain_steps.size()) - 1)];
    if (std::find(flash_frames.begin(), flash_frames.end(), frame) != flash_frames.end())
      r.light_gain *= 1.8;
  }
  return r;
}

/// One sub-frame: the wall (photograph, lit and shadowed), then every mesh by z-buffer. Adds
/// the result to `accumulated` (CV_32FC3); when `object_id` is not null, writes there which
/// item is seen at each pixel (-1 wall, 0 the tracked object, 1.. the others).
void render_scene_sample(const std::vector<kct::PlacedMesh>& items, const Scene& scene,
                         const kct::PinholeCamera& camera, const cv::Mat& background,
                         kct::RenderOptions lighting, bool shadows, const Eigen::Vector3d& focus,
                         cv::Mat& accumulated, cv::Mat* object_id) {
  std::unique_ptr<kct::ShadowMap> shadow;
  if (shadows) {
    // Cover the wall's part of the view around the object as well as the casters.
    const double radius = 0.6 * scene.wall_depth_m * camera.width() / camera.fx();
    shadow = std::make_unique<kct::ShadowMap>(
        items, lighting.light_direction_camera,
        Eigen::Vector3d(focus.x(), focus.y(), 0.5 * (focus.z() + scene.wall_depth_m)), radius, 768);
    lighting.shadow_map = shadow.get();
  }
  const int width = camera.width(), height = camera.height();
  cv::Mat frame(height, width, CV_32FC3);
  cv::Mat zbuffer(height, width, CV_32F, cv::Scalar(std::numeric_limits<float>::infinity()));
  cv::Mat ids(height, width, CV_32S, cv::Scalar(-1));
  const Eigen::Vector3d light = lighting.light_direction_camera.normalized();
  const double wall_lit = lighting.light_gain * std::max(0.0, -light.z());  // wall normal -z
  for (int y = 0; y < height; ++y) {
    const cv::Vec3b* bg = background.ptr<cv::Vec3b>(y);
    cv::Vec3f* out = frame.ptr<cv::Vec3f>(y);
    for (int x = 0; x < width; ++x) {
      // The photograph as it looks under the default lamp at gain 1: light factor 1 there.
      double factor = 0.5 + 0.5 * wall_lit / 0.87;
      if (shadow) {
        const double lit = shadow->lit_fraction(camera.back_project(Eigen::Vector2d(x, y)) *
                                                scene.wall_depth_m);
        factor *= 0.45 + 0.55 * lit;
      }
      out[x] = cv::Vec3f(bg[x][0], bg[x][1], bg[x][2]) * static_cast<float>(factor);
    }
  }
  for (std::size_t k = 0; k < items.size(); ++k) {
    if (!items[k].mesh) continue;
    const kct::RenderOutput r =
        kct::Renderer(items[k].mesh).render(items[k].object_to_camera, camera, lighting);
    for (int y = 0; y < height; ++y) {
      const float* depth = r.depth.ptr<float>(y);
      const cv::Vec3b* color = r.color.ptr<cv::Vec3b>(y);
      float* z = zbuffer.ptr<float>(y);
      int* id = ids.ptr<int>(y);
      cv::Vec3f* out = frame.ptr<cv::Vec3f>(y);
      for (int x = 0; x < width; ++x)
        if (depth[x] > 0.0f && depth[x] < z[x]) {
          z[x] = depth[x];
          id[x] = static_cast<int>(k);
          out[x] = cv::Vec3f(color[x][0], color[x][1], color[x][2]);
        }
    }
  }
  accumulated += frame;
  if (object_id) *object_id = ids;
}

/// Fraction of the object's silhouette (rendered alone on a camera padded by one image size
/// on every side) that is seen in the image, given the composite's item ids.
double visible_fraction(const kct::Renderer& object_renderer, const kct::Pose& pose,
                        const kct::PinholeCamera& camera, const cv::Mat& ids) {
  const int pad_x = camera.width(), pad_y = camera.height();
  const kct::PinholeCamera padded(camera.fx(), camera.fy(), camera.cx() + pad_x,
                                  camera.cy() + pad_y, 3 * camera.width(), 3 * camera.height());
  kct::RenderOptions depth_only;
  depth_only.draw_color = false;
  const int total = cv::countNonZero(object_renderer.render(pose, padded, depth_only).mask());
  if (total == 0) return 0.0;
  return static_cast<double>(cv::countNonZero(ids == 0)) / total;
}

/// Writes one frame (PNG, or JPEG when --jpeg-quality is set); returns its path.
std::string write_frame(const Options& o, const std::string& folder, int index, const cv::Mat& frame) {
  std::string path = folder + kct::frame_file_name(index);
  if (o.jpeg_quality > 0) {
    path = path.substr(0, path.size() - 4) + ".jpg";
    if (!cv::imwrite(path, frame, {cv::IMWRITE_JPEG_QUALITY, o.jpeg_quality}))
      throw std::runtime_error("cannot write " + path);
  } else if (!cv::imwrite(path, frame)) {
    throw std::runtime_error("cannot write " + path);
  }
  return path;
}

int run_scene(const Options& o, std::shared_ptr<const kct::Mesh> mesh,
              const kct::PinholeCamera& camera);

int run(const Options& o) {
  const kct::ModelUnits units(o.model_scale);
  auto mesh = std::make_shared<const kct::Mesh>(kct::load_mesh(o.model, units.metres_per_unit()));
  const kct::PinholeCamera camera(o.fx, o.fy, o.cx, o.cy, o.width, o.height);
  if (o.scene() || o.jpeg_quality > 0 || o.defocus_px > 0.0 || o.shutter_fraction < 1.0)
    return run_scene(o, mesh, camera);
  const kct::SyntheticTrajectory trajectory(o.trajectory, camera, mesh->bounding_box_center(),
                                            mesh->diameter());
  const kct::Renderer renderer(mesh);
  const cv::Mat background = make_background(o.background, camera.size(), o.trajectory.seed);

  std::filesystem::create_directories(o.output_dir);
  const std::string folder = o.output_dir + "/";
  kct::write_intrinsics(folder + "K.txt", camera.K());

  std::unique_ptr<rosbag::Bag> bag;
  if (!o.bag.empty()) {
    const auto parent = std::filesystem::path(o.bag).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    bag = std::make_unique<rosbag::Bag>(o.bag, rosbag::bagmode::Write);
  }

  cv::RNG noise_rng(o.trajectory.seed * 7919 + 3);
  std::vector<kct::Pose> poses;
  const double frame_period = 1.0 / o.trajectory.frame_rate_hz;
  for (int i = 0; i < o.frames; ++i) {
    const kct::FrameLighting lighting = trajectory.frame_lighting(i);
    kct::RenderOptions render_options;
    render_options.light_direction_camera = lighting.light_direction_camera;
    render_options.ambient = lighting.ambient;
    render_options.diffuse = lighting.diffuse;
    render_options.light_gain = lighting.light_gain;

    // Motion blur: average of sub-frame composites spread over one frame interval around
    // the frame time; the ground truth is the pose at the frame time (the centre).
    cv::Mat accumulated(camera.size(), CV_32FC3, cv::Scalar::all(0));
    for (int k = 0; k < o.blur_samples; ++k) {
      const double offset =
          o.blur_samples == 1 ? 0.0 : (double(k) / (o.blur_samples - 1) - 0.5) * frame_period;
      const kct::RenderOutput render =
          renderer.render(trajectory.object_to_camera(i * frame_period + offset), camera,
                          render_options);
      cv::Mat composite = background.clone();
      render.color.copyTo(composite, render.mask());
      cv::accumulate(composite, accumulated);
    }
    accumulated /= static_cast<double>(o.blur_samples);
    if (o.noise_sigma > 0.0) {
      cv::Mat noise(camera.size(), CV_32FC3);
      noise_rng.fill(noise, cv::RNG::NORMAL, 0.0, o.noise_sigma);
      accumulated += noise;
    }
    cv::Mat frame;
    accumulated.convertTo(frame, CV_8UC3);  // rounds and saturates

    const std::string image_path = folder + kct::frame_file_name(i);
    if (!cv::imwrite(image_path, frame)) throw std::runtime_error("cannot write " + image_path);
    const kct::Pose pose = trajectory.frame_pose(i);
    poses.push_back(pose);

    if (bag) {
      std_msgs::Header header;
      header.seq = i;
      header.stamp = ros::Time(kFirstStamp_s + i * frame_period);
      header.frame_id = kFrameId;
      bag->write("/camera/image_raw", header.stamp, to_image_message(frame, header));
      bag->write("/camera/camera_info", header.stamp, to_camera_info(camera, header));
      bag->write("/ground_truth/pose", header.stamp, to_pose_message(pose, header));
    }
  }
  kct::write_pose_file(folder + "pose.txt", poses, units);  // model units, as the mesh
  if (bag) bag->close();

  std::cout << "wrote " << o.frames << " frames (" << kct::to_string(o.trajectory.motion)
            << ", speed " << o.trajectory.speed << ", seed " << o.trajectory.seed << ", object "
            << trajectory.distance_min_m() << "-" << trajectory.distance_max_m() << " m) to "
            << o.output_dir << (o.bag.empty() ? "" : " and " + o.bag) << "\n";
  return 0;
}


/// The scene render of the hard conditions (see the file comment).
int run_scene(const Options& o, std::shared_ptr<const kct::Mesh> mesh,
              const kct::PinholeCamera& camera) {
  if (!o.bag.empty()) throw std::invalid_argument("--bag is not supported with the hard conditions");
  const Eigen::Vector3d center_object = mesh->bounding_box_center();
  std::function<kct::Pose(double)> pose_at;
  double nominal = 0.0, range = 0.0;
  std::unique_ptr<kct::HandheldTrajectory> hand;
  std::unique_ptr<kct::SyntheticTrajectory> opt;
  if (o.handheld) {
    kct::HandheldParams hp = o.hand;
    hp.seed = o.trajectory.seed;
    hp.frames = o.frames;
    hp.frame_rate_hz = o.trajectory.frame_rate_hz;
    hp.distance_m = 0.5 * (o.trajectory.distance_min_m + o.trajectory.distance_max_m);
    hp.distance_range_m = std::min(0.5 * (o.trajectory.distance_max_m - o.trajectory.distance_min_m),
                                   0.5 * hp.distance_m);
    hand = std::make_unique<kct::HandheldTrajectory>(hp, camera, center_object, mesh->diameter());
    nominal = hand->distance_m();
    range = hp.distance_range_m;
    pose_at = [&](double t) { return hand->object_to_camera(t); };
  } else {
    opt = std::make_unique<kct::SyntheticTrajectory>(o.trajectory, camera, center_object,
                                                     mesh->diameter());
    nominal = 0.5 * (opt->distance_min_m() + opt->distance_max_m());
    range = 0.5 * (opt->distance_max_m() - opt->distance_min_m());
    pose_at = [&](double t) { return opt->object_to_camera(t); };
  }
  cv::RNG rng(o.trajectory.seed * 2654435761ULL + 5);
  const Scene scene = make_scene(o, *mesh, nominal, range, rng);
  std::vector<double> gain_steps;
  for (int k = 0; k <= o.frames / 20; ++k) gain_steps.push_back(k == 0 ? 1.0 : rng.uniform(0.55, 1.5));
  std::vector<int> flash_frames;
  for (int k = 0; k < o.frames / 30; ++k) flash_frames.push_back(rng.uniform(5, std::max(6, o.frames)));
  const cv::Mat background = make_background(o.background, camera.size(), o.trajectory.seed);
  const kct::Renderer object_renderer(mesh);

  std::filesystem::create_directories(o.output_dir);
  const std::string folder = o.output_dir + "/";
  kct::write_intrinsics(folder + "K.txt", camera.K());
  cv::RNG noise_rng(o.trajectory.seed * 7919 + 3);
  std::vector<kct::Pose> poses;
  std::vector<double> visible;
  const double frame_period = 1.0 / o.trajectory.frame_rate_hz;
  cv::Mat disc;
  if (o.defocus_px > 0.0) {
    const int r = static_cast<int>(std::ceil(o.defocus_px));
    disc = cv::Mat::zeros(2 * r + 1, 2 * r + 1, CV_32F);
    cv::circle(disc, cv::Point(r, r), r, cv::Scalar(1.0), cv::FILLED, cv::LINE_AA);
    disc /= cv::sum(disc)[0];
  }
  for (int i = 0; i < o.frames; ++i) {
    // Motion blur over the exposure (shutter) centred on the frame time: sub-frame renders
    // along the trajectory, averaged. The ground truth is the pose at the frame time.
    cv::Mat accumulated(camera.size(), CV_32FC3, cv::Scalar::all(0));
    cv::Mat ids;
    const int samples = o.blur_samples;
    for (int k = 0; k < samples; ++k) {
      const double offset_frames =
          samples == 1 ? 0.0 : (double(k) / (samples - 1) - 0.5) * o.shutter_fraction;
      const double t = (i + offset_frames) * frame_period;
      const kct::Pose pose = pose_at(std::max(0.0, t));
      const Eigen::Vector3d center = pose * center_object;
      std::vector<kct::PlacedMesh> items{{mesh, pose}};
      items.insert(items.end(), scene.distractors.begin(), scene.distractors.end());
      if (scene.occluder)
        if (const auto occ = occluder_pose(scene, i + offset_frames, center))
          items.push_back({scene.occluder, *occ});
      const kct::RenderOptions lighting =
          scene_lighting(o, i + offset_frames, gain_steps, flash_frames);
      render_scene_sample(items, scene, camera, background, lighting, o.shadows, center,
                          accumulated, k == samples / 2 ? &ids : nullptr);
    }
    accumulated /= static_cast<double>(samples);
    if (!disc.empty()) cv::filter2D(accumulated, accumulated, -1, disc, cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
    if (o.noise_sigma > 0.0) {
      cv::Mat noise(camera.size(), CV_32FC3);
      noise_rng.fill(noise, cv::RNG::NORMAL, 0.0, o.noise_sigma);
      accumulated += noise;
    }
    cv::Mat frame;
    accumulated.convertTo(frame, CV_8UC3);
    write_frame(o, folder, i, frame);
    poses.push_back(pose_at(i * frame_period));
    visible.push_back(visible_fraction(object_renderer, poses.back(), camera, ids));
  }
  kct::write_pose_file(folder + "pose.txt", poses, kct::ModelUnits(o.model_scale));  // as the mesh
  std::ofstream vis(folder + "visible.txt");
  vis << "# fraction of the object's silhouette inside the image and not occluded, per frame\n";
  for (double v : visible) vis << v << "\n";
  if (!vis) throw std::runtime_error("cannot write " + folder + "visible.txt");
  double max_step_mm = 0.0, max_rot_deg = 0.0;
  for (int i = 1; i < o.frames; ++i) {
    max_step_mm = std::max(max_step_mm, 1000.0 * ((poses[i] * center_object) - (poses[i - 1] * center_object)).norm());
    max_rot_deg = std::max(max_rot_deg, kct::rotation_error_deg(poses[i], poses[i - 1]));
  }
  std::cout << "wrote " << o.frames << " frames (" << (o.handheld ? "hand-held" : kct::to_string(o.trajectory.motion))
            << ", seed " << o.trajectory.seed << ", largest step " << max_step_mm << " mm / "
            << max_rot_deg << " deg a frame, " << scene.distractors.size() << " distractors) to "
            << o.output_dir << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  try {
    options = parse(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "generate_sequence: " << e.what() << "\n" << kUsage;
    return 2;
  }
  try {
    return run(options);
  } catch (const std::exception& e) {
    std::cerr << "generate_sequence: " << e.what() << "\n";
    return 1;
  }
}
