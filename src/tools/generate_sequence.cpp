/// \file generate_sequence.cpp
/// Renders a synthetic tracking sequence with exact ground truth: the model over a real
/// photograph, along a smooth seeded 6-DoF trajectory (OPT-style motion groups), with sensor
/// noise, optional motion blur and lighting changes. Writes a sequence folder (000000.png...,
/// K.txt, pose.txt; see sequence_io.h) and optionally a rosbag. Needs no ROS master.

#include <rosbag/bag.h>
#include <geometry_msgs/PoseStamped.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/model_units.h"
#include "klt_contour_tracker/core/renderer.h"
#include "klt_contour_tracker/core/sequence_io.h"
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
    "  --background PATH        background photograph [opencv-doc's graf1.png]\n";

struct Options {
  std::string model, output_dir, bag, background = kDefaultBackground;
  double model_scale = 1.0;
  int frames = 150, width = 640, height = 480;
  double fx = 525.0, fy = -1.0, cx = -1.0, cy = -1.0;
  kct::TrajectoryParams trajectory;
  double noise_sigma = 2.0;
  int blur_samples = 1;
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
    else throw std::invalid_argument("unknown option " + arg);
  }
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

int run(const Options& o) {
  const kct::ModelUnits units(o.model_scale);
  auto mesh = std::make_shared<const kct::Mesh>(kct::load_mesh(o.model, units.metres_per_unit()));
  const kct::PinholeCamera camera(o.fx, o.fy, o.cx, o.cy, o.width, o.height);
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
