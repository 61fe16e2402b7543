#pragma once
/// \file keypoint_tracker.h
/// Preliminary pose from keypoints (paper Sec. 3.1): Shi-Tomasi corners detected inside the
/// object's projection on a frame whose pose is known, anchored on the mesh surface through
/// the renderer's face-index buffer, tracked into the next frame with pyramidal KLT and a
/// forward-backward check, then PnP + RANSAC.

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/renderer.h"
#include "klt_contour_tracker/core/tracker_params.h"

namespace kct {

/// 2D-3D correspondences that survived RANSAC: the input of the search-area constraint (Sec. 3.4).
struct KeypointInliers {
  std::vector<Eigen::Vector3d> points_object;  ///< model points, object frame, metres
  std::vector<Eigen::Vector2d> points_image;   ///< tracked image positions, px
};

/// Outcome of tracking the anchored keypoints into a new frame.
struct KeypointResult {
  bool success = false;          ///< false: < klt_min_points tracks or inlier rate < klt_min_inlier_ratio
  Pose object_to_camera = Pose::Identity();  ///< PnP pose (valid only when success)
  int tracked = 0;               ///< tracks that passed the forward-backward check
  int inliers = 0;               ///< RANSAC inliers
  double inlier_ratio = 0.0;     ///< inliers / tracked
  double mean_reprojection_px = 0.0;  ///< mean reprojection error of the inliers at the PnP pose
  /// The PnP pose moved implausibly far from the expected pose (keypoint_max_motion_*): not
  /// used (success is false).
  bool implausible_motion = false;
  KeypointInliers inlier_points;      ///< correspondences used by the search area
  /// Anchors whose track failed on this frame (LK status or the forward-backward check; not
  /// those that left the image or failed within klt_window_px of its border), object frame, m:
  /// where something may cover the object.
  std::vector<Eigen::Vector3d> lost_points_object;
  double klt_ms = 0.0;  ///< wall time of the KLT tracking (normalization, pyramids, LK), ms
  double pnp_ms = 0.0;  ///< wall time of PnP + RANSAC + LM, ms
};

/// Where a motion model expects the object in the new frame (ours, not in the paper).
struct KeypointPrediction {
  Pose object_to_camera = Pose::Identity();  ///< predicted pose of the new frame
  /// Start KLT at each keypoint's projection at the predicted pose instead of where it was
  /// (pyramidal LK then only has to find the motion's unexpected part).
  bool initial_flow = true;
  /// > 0: tracks ending farther than this (px) from their predicted position are dropped
  /// before PnP, unless that would drop more than half of them (then the prediction is what
  /// is wrong). 0 = no gating.
  double gate_px = 0.0;
};

/// True when `refined` keeps the KLT inliers' mean reprojection error within
/// `max_increase_px` of the PnP pose's (or when KLT failed: nothing to compare). The tracker
/// re-anchors keypoints only on such poses, so that a refinement that landed in a wrong
/// optimum stays a one-frame error instead of being baked into the new anchors.
bool refined_pose_agrees_with_keypoints(const KeypointResult& keypoints, const Pose& refined,
                                        const PinholeCamera& camera, double max_increase_px);

/// Maximum a posteriori pose from 2D-3D correspondences (`points_object` in metres, object
/// frame; `points_image` in px on the ideal pinhole image of `camera`) and a Gaussian prior on
/// the frame-to-frame motion away from `expected`: independent per axis of the pose_cost.h
/// increment about `center_object`, standard deviation `sigma_rad` for the rotation and
/// `sigma_m` for the centre's translation. Gauss-Newton from `pose` (the PnP pose); the points'
/// variance is their residual variance at `pose`, at least 1 px^2. Directions the points fix
/// stay where PnP put them; those they leave free (points in one strip: the depth, a turn about
/// the strip) stay near the expected pose instead of going wherever the noise sends them.
/// Returns `pose` when a point is not in front of the camera or the solve fails.
Pose pose_with_motion_prior(const std::vector<Eigen::Vector3d>& points_object,
                            const std::vector<Eigen::Vector2d>& points_image,
                            const PinholeCamera& camera, const Pose& pose, const Pose& expected,
                            const Eigen::Vector3d& center_object, double sigma_rad, double sigma_m);

/// Owns the anchored keypoints between frames.
class KeypointTracker {
 public:
  KeypointTracker(std::shared_ptr<const Mesh> mesh, const TrackerParams& params);

  /// Detects corners in `gray` (CV_8UC1) inside the object's projection at `object_to_camera`
  /// and anchors them on the mesh. Returns the number of anchored keypoints.
  /// `same_frame_as_track`: `gray` is the frame the last track() call got (the tracker
  /// re-detects on the frame it just tracked): its KLT image and pyramid are reused.
  int detect(const cv::Mat& gray, const Pose& object_to_camera, const PinholeCamera& camera,
             bool same_frame_as_track = false);

  /// Tracks the anchored keypoints from the previous frame into `gray` and solves PnP from
  /// `object_to_camera_guess` (used as the RANSAC initial guess). Keeps the inliers. With a
  /// `prediction`, KLT starts from the predicted positions and/or gates the tracks by them.
  KeypointResult track(const cv::Mat& gray, const Pose& object_to_camera_guess,
                       const PinholeCamera& camera, const KeypointPrediction* prediction = nullptr);

  /// True when the kept points have thinned below `redetect_ratio` of the last detection.
  bool needs_redetection() const;
  /// Current image positions (px) of the kept keypoints (for debug drawing).
  const std::vector<cv::Point2f>& image_points() const { return image_points_; }
  int num_keypoints() const { return static_cast<int>(image_points_.size()); }
  /// The object's silhouette rendered by the last detect() (CV_8UC1, 255 on the object, not
  /// eroded; the KLT frame's size, i.e. halved for frames wider than klt_max_image_width_px),
  /// e.g. for learning the object's colours at that pose; empty after clear().
  const cv::Mat& object_mask() const { return object_mask_; }
  void clear();
  void set_params(const TrackerParams& params) { params_ = params; }
  /// The object's diameter (metres) and bounding-box centre (object frame) for the motion
  /// plausibility check (keypoint_max_motion_*); the owner computes them once per mesh.
  void set_object_extent(double diameter_m, const Eigen::Vector3d& center_object) {
    diameter_m_ = diameter_m;
    center_object_ = center_object;
  }

 private:
  /// The frame KLT tracks on: `gray` normalized to zero mean / unit variance over
  /// klt_illumination_window_px windows (or a copy of `gray` when the window is 0).
  cv::Mat klt_image(const cv::Mat& gray) const;
  /// How often a frame of `size` is halved for KLT and corners (klt_max_image_width_px).
  int downscale_steps(const cv::Size& size) const;
  /// `gray` halved `steps` times with cv::pyrDown (pixel u there is 2^steps u here).
  static cv::Mat downscale(const cv::Mat& gray, int steps);
  /// True when `measured` moved farther from `expected` than keypoint_max_motion_* allow.
  bool implausible_motion(const Pose& expected, const Pose& measured) const;

  std::shared_ptr<const Mesh> mesh_;
  Renderer renderer_;
  TrackerParams params_;
  cv::Mat previous_gray_;          ///< KLT image of the previous frame (possibly halved)
  cv::Size previous_source_size_;  ///< full-resolution size of that frame
  /// cv::buildOpticalFlowPyramid of previous_gray_ (empty until a track() built it).
  std::vector<cv::Mat> previous_pyramid_;
  cv::Mat object_mask_;  ///< silhouette rendered by the last detect() (KLT frame's size)
  std::vector<cv::Point2f> image_points_;
  std::vector<cv::Point3f> object_points_;
  double diameter_m_ = 0.0;                                  ///< mesh diameter, metres
  Eigen::Vector3d center_object_ = Eigen::Vector3d::Zero();  ///< bounding-box centre
  int detected_count_ = 0;
};

}  // namespace kct
