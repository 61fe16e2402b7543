#include "klt_contour_tracker/core/plausibility.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace kct {

std::string format_number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", value);
  return buffer;
}

std::string truncate_for_message(const std::string& text, std::size_t max_chars) {
  if (text.size() <= max_chars) return text;
  return text.substr(0, max_chars) + "...";
}

std::string implausible_image_size(std::uint64_t width, std::uint64_t height,
                                   std::uint64_t max_pixels) {
  using L = PlausibilityLimits;
  const std::string size = std::to_string(width) + "x" + std::to_string(height) + " px";
  const auto side_ok = [](std::uint64_t side) {
    return side >= static_cast<std::uint64_t>(L::kMinImageSidePx) &&
           side <= static_cast<std::uint64_t>(L::kMaxImageSidePx);
  };
  if (!side_ok(width) || !side_ok(height))
    return "image size " + size + ": each side must be in [" +
           std::to_string(L::kMinImageSidePx) + ", " + std::to_string(L::kMaxImageSidePx) +
           "] px";
  if (max_pixels > 0 && width * height > max_pixels)
    return "image size " + size + " is " + std::to_string(width * height) +
           " pixels, more than max_image_pixels = " + std::to_string(max_pixels) +
           " (raise it to track larger frames; the work per frame grows with the pixels)";
  return "";
}

std::string implausible_intrinsics(double fx, double fy, double cx, double cy, int width,
                                   int height) {
  using L = PlausibilityLimits;
  const std::string size_error = implausible_image_size(
      static_cast<std::uint64_t>(std::max(width, 0)), static_cast<std::uint64_t>(std::max(height, 0)),
      0);
  if (!size_error.empty()) return size_error;
  const double side = std::max(width, height);
  const double f_lo = L::kMinFocalPerSide * side, f_hi = L::kMaxFocalPerSide * side;
  const std::string f_range = "[" + format_number(f_lo) + ", " + format_number(f_hi) +
                              "] px (" + format_number(L::kMinFocalPerSide) + " to " +
                              format_number(L::kMaxFocalPerSide) + " x the larger image side " +
                              format_number(side) + " px)";
  if (!(fx >= f_lo && fx <= f_hi)) return "fx = " + format_number(fx) + " px: allowed " + f_range;
  if (!(fy >= f_lo && fy <= f_hi)) return "fy = " + format_number(fy) + " px: allowed " + f_range;
  const double mx = L::kPrincipalPointMargin * width, my = L::kPrincipalPointMargin * height;
  if (!(cx >= -mx && cx <= width + mx))
    return "cx = " + format_number(cx) + " px: allowed [" + format_number(-mx) + ", " +
           format_number(width + mx) + "] px for an image " + std::to_string(width) + " px wide";
  if (!(cy >= -my && cy <= height + my))
    return "cy = " + format_number(cy) + " px: allowed [" + format_number(-my) + ", " +
           format_number(height + my) + "] px for an image " + std::to_string(height) +
           " px high";
  return "";
}

std::string implausible_camera(const PinholeCamera& camera) {
  return implausible_intrinsics(camera.fx(), camera.fy(), camera.cx(), camera.cy(),
                                camera.width(), camera.height());
}

std::string implausible_pose(const Pose& object_to_camera, double diameter_m,
                             const Eigen::Vector3d& center_object, const PinholeCamera& camera) {
  using L = PlausibilityLimits;
  if (!is_valid_pose(object_to_camera)) return "the pose is not finite or not a rotation";
  const Eigen::Vector3d t = object_to_camera.translation();
  const Eigen::Vector3d c = object_to_camera * center_object;
  const std::string where = "(translation " + format_number(t.x()) + " " + format_number(t.y()) +
                            " " + format_number(t.z()) + " m)";
  if (!(diameter_m > 0.0) || !std::isfinite(diameter_m))
    return "object diameter " + format_number(diameter_m) + " m is not > 0";
  const double z_min = L::kMinDepthPerDiameter * diameter_m;
  const double z_max = std::max(camera.fx(), camera.fy()) * diameter_m / L::kMinProjectedSizePx;
  if (!(c.z() >= z_min && c.z() <= z_max))
    return "the object centre is at depth z = " + format_number(c.z()) + " m " + where +
           ": allowed [" + format_number(z_min) + ", " + format_number(z_max) + "] m (" +
           format_number(L::kMinDepthPerDiameter) +
           " object diameter, where the camera would be inside the object, to where the " +
           format_number(diameter_m) + " m object would project smaller than " +
           format_number(L::kMinProjectedSizePx) + " px)";
  const Eigen::Vector2d p = camera.project(c);
  const double mx = L::kProjectionMargin * camera.width();
  const double my = L::kProjectionMargin * camera.height();
  if (!(p.x() >= -mx && p.x() <= camera.width() + mx && p.y() >= -my &&
        p.y() <= camera.height() + my))
    return "the object centre projects to (" + format_number(p.x()) + ", " +
           format_number(p.y()) + ") px " + where + ": allowed within one image size of the " +
           std::to_string(camera.width()) + "x" + std::to_string(camera.height()) + " image";
  return "";
}

std::string implausible_pose(const Pose& object_to_camera, const Mesh& mesh,
                             const PinholeCamera& camera) {
  return implausible_pose(object_to_camera, mesh.diameter(), mesh.bounding_box_center(), camera);
}

std::string implausible_diameter(double diameter_m) {
  using L = PlausibilityLimits;
  if (diameter_m >= L::kMinDiameterM && diameter_m <= L::kMaxDiameterM) return "";
  return "the model's diameter is " + format_number(diameter_m) + " m after scaling: allowed [" +
         format_number(L::kMinDiameterM) + ", " + format_number(L::kMaxDiameterM) +
         "] m (is the scale right? --model-scale / ~mesh_scale, e.g. 0.001 for millimetres)";
}

}  // namespace kct
