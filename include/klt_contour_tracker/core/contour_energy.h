#pragma once
/// \file contour_energy.h
/// Contour energy of a pose on an image (paper Sec. 3.2, Eq. 5): mean of |grad I . n| over
/// points spread uniformly along the projected model contour and sharp edges.

#include <Eigen/Core>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/contour_extractor.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/visibility_table.h"

namespace kct {

/// Image gradient used by the energy, in intensity units per pixel.
struct GradientImage {
  cv::Mat gx, gy;  ///< CV_32F, d I / d x and d I / d y

  /// Optional Gaussian blur (`blur_sigma_px` > 0; the paper's sigma = 1.1 before the main
  /// optimization, 0 = none), then the 3x3 Sobel operator divided by 8, so a ramp of slope s
  /// intensity units per pixel gives s. `gray` is CV_8UC1 (CV_8UC3 BGR, CV_16UC1 and CV_32FC1
  /// are accepted too). Throws std::invalid_argument for an empty or unsupported image.
  static GradientImage compute(const cv::Mat& gray, double blur_sigma_px);

  bool empty() const { return gx.empty(); }
  int width() const { return gx.cols; }
  int height() const { return gx.rows; }
};

/// Everything behind one energy value, for debug drawing and tests.
struct EnergyDetails {
  double energy = 0.0;                    ///< Eq. 5, intensity units per pixel
  int num_points = 0;                     ///< points kept (inside the image)
  std::vector<ContourSegment> segments;   ///< projected Contour / Sharp edges
  std::vector<Eigen::Vector2d> points;    ///< kept sample points, pixels
  std::vector<Eigen::Vector2d> normals;   ///< unit normal of each point's segment
  std::vector<double> values;             ///< |grad I . n| at each point
};

/// Eq. 5 for a mesh and a visibility table. Sample points: on each projected Contour/Sharp
/// segment of length L, n = max(1, round(L / spacing_px)) points at (k + 0.5) L / n, k < n
/// (the midpoint alone for short segments). The gradient is sampled bilinearly. Points closer
/// than 1 px to the image border (x < 1, y < 1, x > w - 2 or y > h - 2, the gradient image's
/// size) are dropped rather than counted as zero; with no point left the energy is 0.
///
/// Not thread-safe: evaluations reuse the extractor's and this object's scratch buffers
/// (no allocation per call once warm). Use one instance per thread.
class ContourEnergy {
 public:
  /// Bound on the points visited per evaluation: beyond kMaxSamples spacings of contour the
  /// spacing grows to (contour length / kMaxSamples), so at most kMaxSamples + one point per
  /// segment are sampled (ours: 640x480 contours use a few hundred points at 2 px).
  static constexpr int kMaxSamples = 20000;

  /// Uses `extractor` (shared; it must not be used concurrently elsewhere).
  /// Throws std::invalid_argument for a null extractor or spacing_px <= 0.
  ContourEnergy(std::shared_ptr<const ContourExtractor> extractor, double spacing_px);
  /// Builds its own ContourExtractor(mesh, visibility, sharp_edge_angle_deg).
  ContourEnergy(std::shared_ptr<const Mesh> mesh, std::shared_ptr<const VisibilityTable> visibility,
                double sharp_edge_angle_deg, double spacing_px);

  /// Eq. 5 at `object_to_camera` (intensity units per pixel; larger = better match).
  /// Throws std::invalid_argument when `gradient` is empty.
  double evaluate(const Pose& object_to_camera, const PinholeCamera& camera,
                  const GradientImage& gradient) const;

  /// Same value with the segments, kept points, normals and per-point values.
  EnergyDetails evaluate_details(const Pose& object_to_camera, const PinholeCamera& camera,
                                 const GradientImage& gradient) const;

  const ContourExtractor& extractor() const { return *extractor_; }
  double spacing_px() const { return spacing_px_; }

  /// Wall time spent in evaluate() / evaluate_details() since the last reset_times(), and the
  /// part of it spent extracting the contour, ms (for the stage table).
  double evaluation_ms() const { return evaluation_ms_; }
  double extraction_ms() const { return extraction_ms_; }
  void reset_times() { evaluation_ms_ = extraction_ms_ = 0.0; }

 private:
  std::shared_ptr<const ContourExtractor> extractor_;
  double spacing_px_;
  mutable std::vector<ContourSegment> segments_;
  mutable double evaluation_ms_ = 0.0, extraction_ms_ = 0.0;
};

}  // namespace kct
