#pragma once
/// \file sequence_io.h
/// Reading and writing an image sequence folder: frames 000000.png, 000001.png, ... (any
/// png/jpg/jpeg/bmp names, sorted), K.txt (3x3 intrinsics, 9 numbers row-major) and an
/// optional pose.txt (one object_to_camera pose per frame: rotation row-major then
/// translation in model units, 12 numbers per line). The model units are converted here and
/// only here (ModelUnits): a SequenceFolder holds metres.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "klt_contour_tracker/core/model_units.h"
#include "klt_contour_tracker/core/pose.h"

namespace kct {

/// A sequence folder's contents (images are not loaded).
struct SequenceFolder {
  std::vector<std::string> image_paths;  ///< sorted by file name
  cv::Matx33d K;                         ///< intrinsics, pixels
  /// Ground-truth object_to_camera per frame, metres (converted from the model units of
  /// pose.txt); empty without pose.txt. It may hold
  /// more poses than there are images (extra lines are kept), or fewer (no truth at the end).
  std::vector<Pose> poses;
};

/// Reads a sequence folder; pose.txt is in `units` and converted to metres. Throws
/// std::runtime_error naming the file (and line) when the folder or K.txt is missing, K.txt or
/// a pose line is malformed, or there are no images.
SequenceFolder read_sequence(const std::string& directory, const ModelUnits& units = ModelUnits());

/// Reads 9 numbers (whitespace or comma separated) as a row-major 3x3 K; throws
/// std::runtime_error naming the file when it is missing, malformed or fx/fy are not > 0.
cv::Matx33d read_intrinsics(const std::string& path);

/// Reads a pose file: 12 numbers per non-empty line ('#' starts a comment line). Rotations
/// within 1e-2 of orthonormal are projected onto SO(3) (datasets print few decimals); worse
/// ones, a wrong count or a non-number throw std::runtime_error naming the file and line.
std::vector<Pose> read_pose_file(const std::string& path);

/// Writes poses (object_to_camera, metres) in the read_pose_file() format (17 significant
/// digits), their translations converted to `units`. Throws on I/O error.
void write_pose_file(const std::string& path, const std::vector<Pose>& poses_m,
                     const ModelUnits& units = ModelUnits());

/// Width and height of a PNG, JPEG or BMP file read from its header only (no pixel is decoded),
/// so that a frame too large to decode can be refused before it takes the memory. Hand-written:
/// OpenCV 4.6 has no public header-only read (cv::ImageDecoder is internal), and its
/// OPENCV_IO_MAX_IMAGE_PIXELS guard is process-wide and only yields an empty Mat. Throws
/// std::runtime_error naming the file when it cannot be opened or its header is not one of these.
cv::Size read_image_size(const std::string& path);

/// Writes K as 3 lines of 3 numbers. Throws std::runtime_error on I/O error.
void write_intrinsics(const std::string& path, const cv::Matx33d& K);

/// Frame file name used by the writers: 6-digit zero-padded index + ".png".
std::string frame_file_name(int index);

}  // namespace kct
