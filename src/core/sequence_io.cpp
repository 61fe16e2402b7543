#include "klt_contour_tracker/core/sequence_io.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
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

SequenceFolder read_sequence(const std::string& directory, const ModelUnits& units) {
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
  if (fs::exists(pose_path)) sequence.poses = units.to_metres(read_pose_file(pose_path.string()));
  return sequence;
}

void write_pose_file(const std::string& path, const std::vector<Pose>& poses_m,
                     const ModelUnits& units) {
  std::ofstream file(path);
  if (!file) throw std::runtime_error("write_pose_file: cannot create '" + path + "'");
  char number[32];
  for (const Pose& pose : poses_m) {
    const auto row = pose_to_row(units.from_metres(pose));
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

cv::Size read_image_size(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw std::runtime_error("read_image_size: cannot open '" + path + "'");
  auto byte = [&file]() -> int {
    const int c = file.get();
    if (c == std::char_traits<char>::eof()) throw std::out_of_range("end of file");
    return c;
  };
  auto big_endian = [&byte](int bytes) {
    std::uint64_t value = 0;
    for (int i = 0; i < bytes; ++i) value = (value << 8) | static_cast<std::uint64_t>(byte());
    return value;
  };
  auto little_endian = [&byte](int bytes) {
    std::uint64_t value = 0;
    for (int i = 0; i < bytes; ++i) value |= static_cast<std::uint64_t>(byte()) << (8 * i);
    return value;
  };
  // Sizes beyond int are reported as INT_MAX: the caller refuses them anyway.
  auto clamp_int = [](std::uint64_t v) {
    return static_cast<int>(std::min<std::uint64_t>(v, std::numeric_limits<int>::max()));
  };
  try {
    const int b0 = byte(), b1 = byte();
    if (b0 == 0x89 && b1 == 'P') {
      // PNG: 8-byte signature, then the IHDR chunk (length, "IHDR", width, height big-endian).
      file.seekg(16);
      const std::uint64_t width = big_endian(4), height = big_endian(4);
      return cv::Size(clamp_int(width), clamp_int(height));
    }
    if (b0 == 'B' && b1 == 'M') {
      // BMP: BITMAPINFOHEADER width/height (int32 little-endian, height < 0 = top-down).
      file.seekg(18);
      const auto width = static_cast<std::int32_t>(little_endian(4));
      const auto height = static_cast<std::int32_t>(little_endian(4));
      return cv::Size(clamp_int(std::llabs(width)), clamp_int(std::llabs(height)));
    }
    if (b0 == 0xFF && b1 == 0xD8) {
      // JPEG: walk the marker segments to the first start-of-frame (SOF0..SOF15 except DHT
      // 0xC4, JPG 0xC8 and DAC 0xCC): length, precision, height, width (big-endian).
      for (int segments = 0; segments < 10000; ++segments) {
        int marker = byte();
        if (marker != 0xFF) break;
        while (marker == 0xFF) marker = byte();
        if (marker == 0xD8 || (marker >= 0xD0 && marker <= 0xD7) || marker == 0x01) continue;
        const std::uint64_t length = big_endian(2);
        if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC) {
          byte();  // sample precision
          const std::uint64_t height = big_endian(2), width = big_endian(2);
          return cv::Size(clamp_int(width), clamp_int(height));
        }
        if (length < 2 || marker == 0xD9 || marker == 0xDA) break;
        file.seekg(static_cast<std::streamoff>(length - 2), std::ios::cur);
      }
      throw std::runtime_error("read_image_size: '" + path + "': JPEG without a frame header");
    }
  } catch (const std::out_of_range&) {
    throw std::runtime_error("read_image_size: '" + path + "': truncated image header");
  }
  throw std::runtime_error("read_image_size: '" + path + "': not a PNG, JPEG or BMP file");
}

std::string frame_file_name(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", index);
  return name;
}

}  // namespace kct
