/// \file convert_visp_sequence.cpp
/// Converts a ViSP model-based-tracker test sequence (Debian package visp-images-data:
/// /usr/share/visp-images-data/ViSP-images/mbt/cube, mbt-depth/castel, mbt-depth/Castle-simu)
/// into the project's sequence folder (see sequence_io.h): PNG frames, K.txt, pose.txt.
///
///   convert_visp_sequence --images DIR [--prefix NAME] --camera-xml FILE
///                         (--initial-pose FILE.pos | --camera-poses DIR)
///                         --output-dir DIR [--first N] [--max-frames N]
///
///   --images DIR        folder of the frames (pgm/ppm/png/jpg), sorted by name
///   --prefix NAME       only files whose name starts with NAME (castel mixes frames and depth)
///   --camera-xml FILE   ViSP tracker configuration: <camera><px> <py> <u0> <v0> (pixels;
///                       the sequences are without distortion)
///   --initial-pose FILE ViSP vpPoseVector of cMo (the object in the camera frame, ViSP's
///                       cMo is this project's object_to_camera): tx ty tz (metres) then
///                       thetaux thetauy thetauz (axis-angle, radians), one number a line.
///                       pose.txt gets this one line: no ground truth beyond the start.
///   --camera-poses DIR  one 4x4 homogeneous cMo per frame (Castle-simu's CameraPose/,
///                       Camera_001.txt...; read by ViSP's own test straight into cMo),
///                       sorted by name: pose.txt gets all of them (ground truth).
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "klt_contour_tracker/core/sequence_io.h"
#include "tool_args.h"

namespace fs = std::filesystem;

namespace {

const char* kUsage =
    "usage: convert_visp_sequence --images DIR [--prefix NAME] --camera-xml FILE\n"
    "                             (--initial-pose FILE.pos | --camera-poses DIR)\n"
    "                             --output-dir DIR [--first N] [--max-frames N]\n";

std::vector<std::string> sorted_files(const std::string& dir, const std::string& prefix,
                                      const std::vector<std::string>& extensions) {
  if (!fs::is_directory(dir)) throw std::runtime_error(dir + ": not a directory");
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const std::string name = entry.path().filename().string();
    std::string ext = entry.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (name.rfind(prefix, 0) != 0) continue;
    if (std::find(extensions.begin(), extensions.end(), ext) == extensions.end()) continue;
    files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) throw std::runtime_error(dir + ": no files named " + prefix + "*");
  return files;
}

/// The number in <tag>...</tag> inside the file's first <camera> element.
double xml_number(const std::string& text, const std::string& tag, const std::string& path) {
  const auto camera = text.find("<camera>");
  if (camera == std::string::npos) throw std::runtime_error(path + ": no <camera> element");
  const std::regex pattern("<" + tag + ">\\s*([-+0-9.eE]+)\\s*</" + tag + ">");
  std::smatch match;
  const std::string tail = text.substr(camera);
  if (!std::regex_search(tail, match, pattern))
    throw std::runtime_error(path + ": no <" + tag + "> in <camera>");
  return std::stod(match[1].str());
}

std::vector<double> read_numbers(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read");
  std::vector<double> values;
  std::string token;
  while (in >> token) {
    try {
      size_t used = 0;
      values.push_back(std::stod(token, &used));
      if (used != token.size()) break;  // e.g. "-0.456V1": ViSP's trailing tag
    } catch (const std::logic_error&) {
      break;
    }
  }
  return values;
}

}  // namespace

int main(int argc, char** argv) {
  std::string images, prefix, xml, initial_pose, camera_poses, output;
  int first = 0, max_frames = -1;
  try {
    using kct_tools::store;
    if (!kct_tools::parse_tool_options(argc, argv,
                                       {{"--images", store(images)},
                                        {"--prefix", store(prefix)},
                                        {"--camera-xml", store(xml)},
                                        {"--initial-pose", store(initial_pose)},
                                        {"--camera-poses", store(camera_poses)},
                                        {"--output-dir", store(output)},
                                        {"--first", store(first)},
                                        {"--max-frames", store(max_frames)}})) {
      std::cout << kUsage;
      return 0;
    }
    if (images.empty() || xml.empty() || output.empty() || initial_pose.empty() == camera_poses.empty())
      throw std::invalid_argument("need --images, --camera-xml, --output-dir and one of "
                                  "--initial-pose / --camera-poses");
    if (first < 0) throw std::invalid_argument("--first must be >= 0");
  } catch (const std::exception& e) {
    std::cerr << "convert_visp_sequence: " << e.what() << "\n" << kUsage;
    return 2;
  }
  try {
    std::vector<std::string> frames =
        sorted_files(images, prefix, {".pgm", ".ppm", ".png", ".jpg", ".jpeg"});
    std::vector<kct::Pose> poses;
    if (!camera_poses.empty()) {
      for (const std::string& path : sorted_files(camera_poses, "", {".txt"})) {
        const std::vector<double> v = read_numbers(path);
        if (v.size() < 12) throw std::runtime_error(path + ": expected a 4x4 matrix");
        std::array<double, 12> row{};
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 3; ++c) row[3 * r + c] = v[4 * r + c];
          row[9 + r] = v[4 * r + 3];
        }
        poses.push_back(kct::pose_from_row(row));
      }
      if (poses.size() != frames.size())
        throw std::runtime_error(camera_poses + ": " + std::to_string(poses.size()) + " poses for " +
                                 std::to_string(frames.size()) + " frames");
    } else {
      const std::vector<double> v = read_numbers(initial_pose);
      if (v.size() < 6) throw std::runtime_error(initial_pose + ": expected tx ty tz tux tuy tuz");
      const Eigen::Vector3d theta_u(v[3], v[4], v[5]);
      kct::Pose pose = kct::Pose::Identity();
      if (theta_u.norm() > 0.0)
        pose.linear() = Eigen::AngleAxisd(theta_u.norm(), theta_u.normalized()).toRotationMatrix();
      pose.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
      poses.push_back(pose);
    }
    if (first >= static_cast<int>(frames.size())) throw std::runtime_error("--first beyond the last frame");
    if (first > 0) {
      if (poses.size() == 1)
        throw std::runtime_error("--first needs per-frame poses (the initial pose is for frame 0)");
      frames.erase(frames.begin(), frames.begin() + first);
      poses.erase(poses.begin(), poses.begin() + first);
    }
    if (max_frames > 0 && static_cast<int>(frames.size()) > max_frames) frames.resize(max_frames);
    if (poses.size() > frames.size()) poses.resize(frames.size());

    std::ifstream in(xml);
    if (!in) throw std::runtime_error(xml + ": cannot read");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const double px = xml_number(text, "px", xml), py = xml_number(text, "py", xml);
    const double u0 = xml_number(text, "u0", xml), v0 = xml_number(text, "v0", xml);

    fs::create_directories(output);
    for (size_t i = 0; i < frames.size(); ++i) {
      const cv::Mat image = cv::imread(frames[i], cv::IMREAD_UNCHANGED);
      if (image.empty()) throw std::runtime_error(frames[i] + ": cannot read image");
      const std::string path = output + "/" + kct::frame_file_name(static_cast<int>(i));
      if (!cv::imwrite(path, image)) throw std::runtime_error(path + ": cannot write");
    }
    kct::write_intrinsics(output + "/K.txt", cv::Matx33d(px, 0, u0, 0, py, v0, 0, 0, 1));
    kct::write_pose_file(output + "/pose.txt", poses);
    std::cout << "wrote " << frames.size() << " frames, " << poses.size()
              << (poses.size() > 1 ? " ground-truth poses" : " initial pose") << " to " << output << "\n";
  } catch (const std::exception& e) {
    std::cerr << "convert_visp_sequence: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
