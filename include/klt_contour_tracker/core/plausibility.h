#pragma once
/// \file plausibility.h
/// Plausibility checks of what comes from outside (camera_info, K.txt, ~init, pose.txt, mesh
/// files) before it reaches the tracker: values that are finite but absurd (fx = 1e-300, a pose
/// 1e300 m away, a 20000x20000 frame) would otherwise make the work per frame unbounded or the
/// output meaningless. Every check returns "" when the input is plausible, else one sentence
/// naming the field, the value and the allowed range (values longer than 64 characters are
/// truncated with "...").

#include <cstdint>
#include <string>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"

namespace kct {

/// Bounds applied by the checks below (ours, chosen so that every real camera and object
/// passes with a wide margin).
struct PlausibilityLimits {
  /// Smallest image side, px: below it the 3x3 gradient, the KLT window (21 px) and the
  /// contour have nothing to work on.
  static constexpr int kMinImageSidePx = 32;
  /// Largest image side, px (the pixel count is bounded by TrackerParams::max_image_pixels).
  static constexpr int kMaxImageSidePx = 16384;
  /// Focal lengths fx, fy in [kMinFocalPerSide, kMaxFocalPerSide] x the larger image side:
  /// 0.05 is a 169 deg field of view across that side (wider than any pinhole or fisheye
  /// model the tracker undistorts to), 50 a 1.1 deg telephoto.
  static constexpr double kMinFocalPerSide = 0.05;
  static constexpr double kMaxFocalPerSide = 50.0;
  /// The principal point may lie up to one image width (height) outside the image (crops and
  /// ROIs of a larger sensor): cx in [-w, 2w], cy in [-h, 2h].
  static constexpr double kPrincipalPointMargin = 1.0;
  /// Depth of the object's bounding-box centre, in object diameters: at least 0.5 (nearer,
  /// the camera is inside the object's bounding sphere) ...
  static constexpr double kMinDepthPerDiameter = 0.5;
  /// ... and at most fx * diameter / kMinProjectedSizePx (farther, the whole object would
  /// project smaller than this many pixels: nothing left to track).
  static constexpr double kMinProjectedSizePx = 1.0;
  /// The bounding-box centre projects at most one image size outside the image.
  static constexpr double kProjectionMargin = 1.0;
  /// Mesh diameter after scaling, metres: 0.1 mm to 10 km.
  static constexpr double kMinDiameterM = 1e-4;
  static constexpr double kMaxDiameterM = 1e4;
};

/// "" when a width x height image (unsigned, as in a ROS message) is within
/// [kMinImageSidePx, kMaxImageSidePx] per side and has at most `max_pixels` pixels, else the
/// reason (e.g. "image size 100000x1 px: each side must be in [32, 16384] px").
std::string implausible_image_size(std::uint64_t width, std::uint64_t height,
                                   std::uint64_t max_pixels);

/// "" when fx, fy, cx, cy (pixels) are plausible for a width x height image (limits above; the
/// size itself is checked by implausible_image_size() without a pixel bound), else the reason.
/// Usable on K.txt / camera_info values before a PinholeCamera is built.
std::string implausible_intrinsics(double fx, double fy, double cx, double cy, int width,
                                   int height);
/// Same for a camera.
std::string implausible_camera(const PinholeCamera& camera);

/// "" when `object_to_camera` is finite, a rotation, and puts the bounding-box centre of an
/// object of `diameter_m` (centre `center_object`, object frame, metres) at a depth in
/// [kMinDepthPerDiameter * d, max(fx, fy) * d / kMinProjectedSizePx] and projecting within
/// kProjectionMargin image sizes of the image; else the reason.
std::string implausible_pose(const Pose& object_to_camera, double diameter_m,
                             const Eigen::Vector3d& center_object, const PinholeCamera& camera);
/// Same with the mesh's diameter and bounding-box centre.
std::string implausible_pose(const Pose& object_to_camera, const Mesh& mesh,
                             const PinholeCamera& camera);

/// "" when a mesh diameter (metres, after scaling) is in [kMinDiameterM, kMaxDiameterM].
std::string implausible_diameter(double diameter_m);

/// `text` cut to `max_chars` characters with "..." appended when longer (for echoing values
/// that come from outside, e.g. a 10,000-character encoding string).
std::string truncate_for_message(const std::string& text, std::size_t max_chars = 64);

/// A double in a message: "%g" (so 1e-300 stays readable, unlike std::to_string's "0.000000").
std::string format_number(double value);

}  // namespace kct
