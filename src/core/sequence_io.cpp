#include "klt_contour_tracker/core/sequence_io.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace kct {
namespace {

namespace fs = std::filesystem;

/// Parses whitespace/comma separated numbers; false on a token that is not a finite number.
bool parse_numbers(std::string text, std::vector<double>& numbers, std::string& bad_token) {
  std::replace(text.begin(), text.end(), ',', ' ');
  std::istringstream stream(text);
  std::string token;
  numbers.clear();
  while (stream >> token) {
    std::size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(token, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != token.size() || !std::isfinite(value)) {
      bad_token = token;
      return false;
    }
    numbers.push_back(value);
  }
  return true;
}

bool is_image_name(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp";
}

}  // namespace

cv::Matx33d read_intrinsics(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error("read_intrinsics: cannot open '" + path + "'");
  std::stringstream content;
  content << file.rdbuf();
  std::vector<double> numbers;
  std::string bad;
  if (!parse_numbers(content.str(), numbers, bad))
    throw std::runtime_error("read_intrinsics: '" + path + "': not a number: '" + bad + "'");
  if (numbers.size() != 9)
    throw std::runtime_error("read_intrinsics: '" + path + "': expected 9 numbers (3x3 K), got " +
                             std::to_string(numbers.size()));
  cv::Matx33d K;
  for (int i = 0; i < 9; ++i) K.val[i] = numbers[i];
  if (!(K(0, 0) > 0.0 && K(1, 1) > 0.0))
    throw std::runtime_error("read_intrinsics: '" + path + "': fx and fy must be > 0");
  return K;
}

std::vector<Pose> read_pose_file(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::runtime_error("read_pose_file: cannot open '" + path + "'");
  std::vector<Pose> poses;
  std::string line;
  std::vector<double> numbers;
  for (int line_number = 1; std::getline(file, line); ++line_number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::string where = "read_pose_file: '" + path + "' line " + std::to_string(line_number);
    std::string bad;
    if (!parse_numbers(line, numbers, bad))
      throw std::runtime_error(where + ": not a number: '" + bad + "'");
    if (numbers.size() != 12)
      throw std::runtime_error(where + ": expected 12 numbers (rotation row-major, translation), got " +
                               std::to_string(numbers.size()));
    std::array<double, 12> row;
    std::copy(numbers.begin(), numbers.end(), row.begin());
    Pose pose = pose_from_row(row);
    const Eigen::Matrix3d r = pose.linear();
    if ((r * r.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-2 || r.determinant() <= 0.0)
      throw std::runtime_error(where + ": the 3x3 block is not a rotation");
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
    pose.linear() = svd.matrixU() * svd.matrixV().transpose();
    poses.push_back(pose);
  }
  return poses;
}

SequenceFolder read_sequence(const std::string& directory) {
  if (!fs::is_directory(directory))
    throw std::runtime_error("read_sequence: '" + directory + "' is not a directory");
  SequenceFolder sequence;
  for (const auto& entry : fs::directory_iterator(directory))
    if (entry.is_regular_file() && is_image_name(entry.path()))
      sequence.image_paths.push_back(entry.path().string());
  std::sort(sequence.image_paths.begin(), sequence.image_paths.end());
  if (sequence.image_paths.empty())
    throw std::runtime_error("read_sequence: no images (png/jpg/jpeg/bmp) in '" + directory + "'");
  const fs::path k_path = fs::path(directory) / "K.txt";
  if (!fs::exists(k_path))
    throw std::runtime_error("read_sequence: missing intrinsics file '" + k_path.string() + "'");
  sequence.K = read_intrinsics(k_path.string());
  const fs::path pose_path = fs::path(directory) / "pose.txt";
  if (fs::exists(pose_path)) sequence.poses = read_pose_file(pose_path.string());
  return sequence;
}

void write_pose_file(const std::string& path, const std::vector<Pose>& poses) {
  std::ofstream file(path);
  if (!file) throw std::runtime_error("write_pose_file: cannot create '" + path + "'");
  char number[32];
  for (const Pose& pose : poses) {
    const auto row = pose_to_row(pose);
    for (int i = 0; i < 12; ++i) {
      std::snprintf(number, sizeof(number), "%.17g", row[i]);
      file << number << (i < 11 ? ' ' : '\n');
    }
  }
  if (!file) throw std::runtime_error("write_pose_file: error writing '" + path + "'");
}

void write_intrinsics(const std::string& path, const cv::Matx33d& K) {
  std::ofstream file(path);
  if (!file) throw std::runtime_error("write_intrinsics: cannot create '" + path + "'");
  char number[32];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      std::snprintf(number, sizeof(number), "%.17g", K(r, c));
      file << number << (c < 2 ? ' ' : '\n');
    }
  if (!file) throw std::runtime_error("write_intrinsics: error writing '" + path + "'");
}

std::string frame_file_name(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", index);
  return name;
}

}  // namespace kct
