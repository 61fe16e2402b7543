#pragma once
/// \file feature_relocalizer.h
/// Tracking by detection for textured objects (ours, beyond the paper): ORB features of
/// keyframes (frames whose pose is trusted: the given initial pose, later good frames from
/// other viewpoints) anchored on the mesh, matched in a new frame and solved by PnP + RANSAC.
/// The result is an absolute pose, independent of the track's history: it re-acquires a lost
/// object and catches a track that KLT anchors hold confidently at a wrong pose (anchors laid
/// after a blurred jerk, or on an occluder), which the frame-to-frame pipeline cannot notice.
/// Untextured objects give few features (their corners, whose patches hold background too):
/// a plain box over a fixed textured background is found (session tests), the benchmark's plain
/// toy and castle over changing backgrounds were not.
///
/// Why not KLT keyframes or a template: ORB (OpenCV) is invariant to in-plane rotation and
/// scale (8-level pyramid), binary descriptors match in a few ms on the CPU, and the matches
/// need no motion prior, so the object may be anywhere in the frame.

#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/renderer.h"

namespace kct {

/// Settings of the relocalizer (all ours).
struct FeatureRelocalizerSettings {
  int max_features = 500;            ///< ORB features detected per keyframe (inside the silhouette)
  /// ORB features detected in a frame (or region) to search. Many more than a keyframe has: in a
  /// cluttered frame ORB's strongest corners are the background's, and with 500 a small object
  /// kept 5 right of 51 matches (hard chest, leave-the-image, frame 1); 3000 cost ~7 ms a frame.
  int frame_features = 3000;
  int fast_threshold = 12;           ///< ORB's FAST threshold (intensity levels)
  int max_keyframes = 12;            ///< keyframes kept (the first, the given pose, always)
  /// A new keyframe's rotation must differ from every stored one's by at least this.
  double keyframe_min_angle_deg = 10.0;
  double match_ratio = 0.8;          ///< Lowe's ratio test on Hamming distances
  double ransac_reprojection_px = 4.0;   ///< RANSAC inlier threshold, px
  /// USAC iterations (PROSAC sampling on matches ordered by descriptor distance, MSAC score,
  /// local optimization): found at 10-15 % right matches, where EPnP-RANSAC is not.
  int ransac_iterations = 2000;
  /// Fewer PnP inliers: not found. On 8 hard sequences finds with 15-19 inliers were right
  /// 47 times and wrong 30, with 20-29 right 71 and wrong 12, with 50 or more never wrong.
  int min_inliers = 20;
  /// Inliers / matches below this: not found. 0: with 3000 frame features most matches of a
  /// small object in clutter are wrong, and the inlier count alone sorts right from wrong.
  double min_inlier_ratio = 0.0;
  int mask_erosion_px = 3;           ///< keyframe features stay this far inside the silhouette

  /// Throws std::invalid_argument naming the first bad field and its allowed range.
  void validate() const;
};

/// A pose found by FeatureRelocalizer::locate().
struct Relocalization {
  bool found = false;
  Pose object_to_camera = Pose::Identity();  ///< valid when found, metres
  int matches = 0;        ///< ratio-test matches to the keyframes
  int inliers = 0;        ///< PnP RANSAC inliers
  double mean_reprojection_px = 0.0;  ///< of the inliers at the pose
};

/// Keyframe database + detection. Not thread-safe.
class FeatureRelocalizer {
 public:
  /// Throws std::invalid_argument for an empty mesh or invalid settings.
  FeatureRelocalizer(std::shared_ptr<const Mesh> mesh, const FeatureRelocalizerSettings& settings = {});

  /// Stores `gray` (CV_8UC1, undistorted, the camera's size) at the trusted `object_to_camera`
  /// as a keyframe: its ORB features inside the eroded silhouette, anchored on the mesh. When
  /// the database is full the newest keyframe but the first is replaced. Returns the number of
  /// anchored features (a keyframe with fewer than min_inliers is not stored).
  int add_keyframe(const cv::Mat& gray, const Pose& object_to_camera, const PinholeCamera& camera);
  /// True when no keyframe's rotation is within keyframe_min_angle_deg of `object_to_camera`'s.
  bool wants_keyframe(const Pose& object_to_camera) const;

  /// Finds the object in `gray` inside `region` (px; empty = the whole frame): ORB features,
  /// ratio-test matches to every keyframe, PnP + USAC (PROSAC) on the matches ordered by
  /// distance, Levenberg-Marquardt on the inliers.
  Relocalization locate(const cv::Mat& gray, const PinholeCamera& camera,
                        const cv::Rect& region = cv::Rect()) const;

  /// The object's bounding rectangle at `object_to_camera`, grown by `margin` x its larger side
  /// plus `grow_px` on every side, clipped to the image (px; empty when it lies outside): a
  /// region for locate(). The whole image when a corner of the object is behind the camera.
  cv::Rect region_around(const Pose& object_to_camera, const PinholeCamera& camera,
                         double margin, double grow_px = 0.0) const;

  int keyframes() const { return static_cast<int>(keyframes_.size()); }
  void clear() { keyframes_.clear(); }

 private:
  struct Keyframe {
    cv::Mat descriptors;                 ///< CV_8U, one ORB descriptor a row
    std::vector<cv::Point3f> points_object;
    Eigen::Matrix3d rotation;  ///< object_to_camera rotation of the keyframe
  };

  std::shared_ptr<const Mesh> mesh_;
  FeatureRelocalizerSettings settings_;
  Renderer renderer_;
  cv::Ptr<cv::ORB> orb_;        ///< keyframes: max_features
  cv::Ptr<cv::ORB> frame_orb_;  ///< frames to search: frame_features
  Eigen::Vector3d center_object_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> corners_object_;  ///< bounding-box corners
  std::vector<Keyframe> keyframes_;
};

}  // namespace kct
