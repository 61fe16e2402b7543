#pragma once
/// \file surface_texture.h
/// The object's surface colours, learned from a frame at a known pose (the initial one), and how
/// well a pose lays them over another frame. Silhouette, contour energy and colour histograms
/// cannot tell a pose from the same object turned about a symmetry axis (a can turned about its
/// axis) or into a view with the same outline; the surface's own pattern can. Ours: the paper's
/// keypoints carry texture only from frame to frame, so a wrong pose they are anchored at stays
/// wrong. The colours are sampled at points on the mesh (object frame), so they are compared at
/// any pose; the score is a normalized cross-correlation, so a global gain or offset of the
/// light does not change it.

#include <Eigen/Core>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"

namespace kct {

/// How well a pose lays the learned colours over a frame.
struct TextureAgreement {
  /// Normalized cross-correlation of the learned and the observed colours of the points the pose
  /// shows, pooled over the three channels, in [-1, 1]; 0 when too few points were compared.
  double correlation = 0.0;
  int points = 0;  ///< learned points the pose shows (facing the camera, inside the image)
};

/// The best of a grid of shifted poses (SurfaceTexture::best_shift()).
struct TextureShift {
  Pose object_to_camera = Pose::Identity();  ///< the shifted pose
  Eigen::Vector3d shift_camera_m = Eigen::Vector3d::Zero();  ///< its shift, camera frame, metres
  TextureAgreement agreement;  ///< its agreement (correlation -1, points 0 when none was scored)
};

/// The pose near a given one whose colours agree best (SurfaceTexture::align()).
struct TextureAlignment {
  Pose object_to_camera =
      Pose::Identity();        ///< the best pose found (the given one if none was better)
  TextureAgreement agreement;  ///< its agreement
  int evaluations = 0;         ///< agreements computed
};

/// A frame's neighbourhood of the object, band-passed (see SurfaceTexture::prepare()).
struct PreparedFrame {
  cv::Mat band;   ///< CV_32FC3: fine minus coarse smoothing, at `scale` of the frame
  cv::Mat fine;   ///< CV_32FC3: the fine smoothing alone (colours, for learn()'s chromaticity)
  cv::Rect roi;   ///< the frame's pixels it covers
  double scale = 1.0;  ///< band pixels per frame pixel
};

/// Surface points with their colours, learned at one pose.
class SurfaceTexture {
 public:
  /// Points are compared only when at least this many are shown.
  static constexpr int kMinPoints = 30;

  explicit SurfaceTexture(std::shared_ptr<const Mesh> mesh);

  /// Learns the colours `bgr` (CV_8UC3, undistorted, the camera's size) shows at
  /// `object_to_camera`: up to `max_points` points on a grid over the object's image, off its
  /// outline (where the background blends in). Replaces what was learned before.
  void learn(const cv::Mat& bgr, const Pose& object_to_camera, const PinholeCamera& camera,
             int max_points = 400);
  void clear() {
    points_object_.clear();
    normals_object_.clear();
    colors_.clear();
    textured_ = color_pattern_ = false;
  }
  /// Learned, and the band-passed colours of the typical point are far enough from zero to
  /// tell poses apart: a flat-shaded uniform object has a pattern only along its creases.
  /// Smooth shading and the creases of a many-faced model still pass (the benchmark's orange
  /// toy and grey castle do).
  bool ready() const { return textured_; }
  /// ready(), and the pattern is in the colours' chromaticity, not only in their brightness:
  /// printed or painted colours, which shading and light do not make. A stronger cue.
  bool has_color_pattern() const { return color_pattern_; }
  int size() const { return static_cast<int>(points_object_.size()); }

  /// The object's neighbourhood in `bgr` (a disc of one diameter around its centre at
  /// `object_to_camera`, which covers every pose turned about the centre), scaled so that the
  /// object spans about 128 px, and band-passed: smoothed by 1 % minus 5 % of the object's
  /// size. The fine smoothing lets a pose a few pixels off compare the same pattern; the coarse
  /// one removes shading and light gradients, which change with the light and the view while the
  /// surface's pattern does not. One per frame serves every pose scored on it.
  PreparedFrame prepare(const cv::Mat& bgr, const Pose& object_to_camera,
                        const PinholeCamera& camera) const;
  /// Agreement of the learned colours with `prepared` (from prepare()) at `object_to_camera`.
  TextureAgreement agreement(const PreparedFrame& prepared, const Pose& object_to_camera,
                             const PinholeCamera& camera) const;

  /// The pose within `max_turn_rad` (turns about the object's centre, about each camera axis)
  /// and `max_shift_m` (of the centre, along each camera axis) of `object_to_camera` whose
  /// colours agree best with `prepared`, by a local search from `object_to_camera` of at most
  /// `max_evaluations` agreements, coarse to fine (first on the band smoothed by a further 4 %
  /// of the object's size, whose correlation peak is wider, then on the band). A pose KLT's anchors
  /// hold 10-20 deg off about no axis of the object's (after an occlusion or a blurred jerk:
  /// best_shift() and the texture check's turns about the object's axes miss it) is found where its
  /// surface pattern is. Never worse than `object_to_camera`'s own agreement.
  TextureAlignment align(const PreparedFrame& prepared, const Pose& object_to_camera,
                         const PinholeCamera& camera, double max_turn_rad, double max_shift_m,
                         int max_evaluations) const;

  /// The pose shifted in the camera frame, laterally by -steps .. steps x `lateral_step_m` along
  /// x and y and in depth by -1, 0, 1 x `depth_step_ratio` of its centre's depth (the unshifted
  /// pose excluded), whose colours agree best with `prepared` over at least kMinPoints points.
  /// A pose whose outline the contour holds a few centimetres off (after a blurred jerk, its
  /// keypoints anchored there) is found where its printed surface is.
  TextureShift best_shift(const PreparedFrame& prepared, const Pose& object_to_camera,
                          const PinholeCamera& camera, double lateral_step_m, int steps,
                          double depth_step_ratio) const;

 private:

  std::shared_ptr<const Mesh> mesh_;
  double diameter_m_ = 0.0;
  Eigen::Vector3d center_object_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> points_object_;   ///< object frame, metres
  std::vector<Eigen::Vector3d> normals_object_;  ///< unit, outward, object frame
  std::vector<Eigen::Vector3f> colors_;          ///< B, G, R in [0, 255]
  bool textured_ = false;
  bool color_pattern_ = false;
};

}  // namespace kct
