#pragma once
/// \file tracker.h
/// The per-frame pipeline (paper Sec. 3): keypoint pose or extrapolation, then contour-energy
/// refinement, then re-anchoring of the keypoints from the final pose. The core is pushed
/// frames: `track()` is called once per image, it owns no thread and does no I/O.

#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/keypoint_tracker.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/stage_times.h"
#include "klt_contour_tracker/core/tracker_params.h"

namespace kct {

class PoseRefiner;
struct RefineResult;
class ContourExtractor;
class MotionModel;
class RegionCost;
class MotionPriorCost;
class WorkerThreads;

/// One camera image. 8-bit grey (CV_8UC1) or BGR (CV_8UC3); undistorted unless the camera
/// given to the tracker has distortion coefficients.
struct Frame {
  cv::Mat image;
  double stamp_s = 0.0;  ///< seconds, only used to detect time going backwards
};

/// Why a frame's pose is what it is.
enum class TrackStatus {
  kNotInitialized,  ///< no pose given yet: nothing to track from
  kInitialized,     ///< the frame got the pose given to initialize()
  kKeypoints,       ///< preliminary pose from KLT + PnP
  kExtrapolated,    ///< KLT failed: preliminary pose extrapolated from the two previous poses
  kInvalidInput,    ///< empty image, wrong type or size, more than max_image_pixels: frame skipped, state unchanged
  kReacquired,      ///< reacquire(): preliminary pose = the given pose, widened search area
};
const char* to_string(TrackStatus status);

/// Result of one frame. `object_to_camera` is meaningful unless the status is
/// kNotInitialized or kInvalidInput.
struct TrackResult {
  TrackStatus status = TrackStatus::kNotInitialized;
  Pose object_to_camera = Pose::Identity();
  Pose preliminary_object_to_camera = Pose::Identity();  ///< before refinement
  KeypointResult keypoints;       ///< the KLT stage's statistics
  bool refined = false;           ///< the contour refinement ran
  double energy_before = 0.0;     ///< contour energy (Eq. 5) at the preliminary pose, frame unblurred
  double energy_after = 0.0;      ///< contour energy at the final pose, frame unblurred
  int hops = 0;                   ///< basin-hopping hops run (all stages)
  double frame_time_ms = 0.0;     ///< wall time spent in track()
  StageTimes times;               ///< where frame_time_ms went, per stage
  std::string message;            ///< human-readable detail for kInvalidInput
};

/// Tracks one rigid object in one camera's image stream.
class Tracker {
 public:
  /// Throws std::invalid_argument if the parameters do not validate, the camera is implausible
  /// (core/plausibility.h) or the mesh's diameter is outside [1e-4, 1e4] m.
  Tracker(std::shared_ptr<const Mesh> mesh, const PinholeCamera& camera, const TrackerParams& params);
  ~Tracker();

  /// The next frame passed to track() has this pose; tracking continues from it.
  /// Throws std::invalid_argument for a non-finite pose, one with the object behind the camera
  /// or an implausible one (implausible_pose(): depth, projection; the message says why).
  void initialize(const Pose& object_to_camera);
  /// Drops the track; track() returns kNotInitialized until initialize() is called again.
  void reset();
  /// Drops the keypoints anchored so far; the next frame's KLT fails and its pose comes from
  /// the extrapolation and the refinement, which anchor new ones (the tracking session calls it
  /// when it judges a frame whose keypoints were anchored on an unverified pose to be bad).
  void forget_keypoints() { keypoints_.clear(); }
  bool is_initialized() const { return state_ != State::kWaiting; }

  /// Runs the pipeline on one frame.
  TrackResult track(const Frame& frame);

  /// Re-acquisition of a lost track (ours, not in the paper): refines `around` (e.g. the last
  /// good pose, object_to_camera) on `frame` inside the extrapolated search box (Sec. 3.4)
  /// scaled by `search_scale` (>= 1; rotation bound capped at 180 deg), without keypoints, then
  /// re-anchors the keypoints on the result and continues tracking from it. Without refinement
  /// (klt_only) the pose is `around`. Status kReacquired, or kInvalidInput as in track().
  /// Throws std::invalid_argument for an invalid `around` or search_scale < 1.
  TrackResult reacquire(const Frame& frame, const Pose& around, double search_scale);
  /// The refinement step of reacquire() alone: the track is not changed (to compare several
  /// re-acquisition hypotheses on one frame). Same exceptions as reacquire().
  TrackResult refine_hypothesis(const Frame& frame, const Pose& around, double search_scale);
  /// refine_hypothesis() for several poses on one frame (converted once); one result per pose,
  /// in order. All kInvalidInput when the frame is unusable. With num_threads >= 2 (and the
  /// coarse_to_fine optimizer without region or motion-prior cue) the hypotheses are refined on
  /// two threads, with the same results. The first result's frame_time_ms is the whole call's
  /// wall time, the others' 0. `shift_search` false: no image-plane shift search
  /// (shift_search_diameters), for hypotheses whose place is known (only their rotation is in
  /// question).
  std::vector<TrackResult> refine_hypotheses(const Frame& frame, const std::vector<Pose>& around,
                                             double search_scale, bool shift_search = true);
  /// The rest of reacquire(): tracking continues from `result` (a refine_hypothesis() result on
  /// `frame`; anything else is ignored), keypoints re-anchored there; adds the time to it.
  void adopt(const Frame& frame, TrackResult& result);

  /// Changes the intrinsics (e.g. a new camera_info); keeps the track. Throws
  /// std::invalid_argument for an implausible camera (implausible_camera()).
  void set_camera(const PinholeCamera& camera);
  const PinholeCamera& camera() const { return camera_; }
  /// Replaces the parameters (validated; throws std::invalid_argument); keeps the track.
  void set_params(const TrackerParams& params);
  const TrackerParams& params() const { return params_; }
  const Mesh& mesh() const { return *mesh_; }
  /// The refiner's contour extractor (with its visibility table), e.g. for drawing the model's
  /// contour; null when the refinement is off.
  const ContourExtractor* contour_extractor() const;
  /// `image` in colour, undistorted as the pipeline sees it (CV_8UC3); empty for a grey image.
  cv::Mat undistorted_color(const cv::Mat& image) const { return to_bgr(image); }
  /// `image` in grey, undistorted as the pipeline sees it (CV_8UC1).
  cv::Mat undistorted_gray(const cv::Mat& image) const { return to_gray(image); }
  /// kInvalidInput message for a frame track() cannot use, "" when the frame is fine.
  std::string check_frame(const Frame& frame) const;
  /// Mesh diameter, metres (computed once).
  double diameter_m() const { return diameter_m_; }
  /// The mesh's bounding-box centre, object frame, metres (computed once).
  const Eigen::Vector3d& center_object() const { return center_object_; }
  /// Last pose output (valid when is_initialized()).
  const Pose& last_pose() const { return pose_i1_; }

 private:
  enum class State { kWaiting, kPendingFirstFrame, kTracking };
  /// Copies a refinement's pose (when valid) and statistics into `result`.
  static void apply_refinement(const RefineResult& refined, TrackResult& result);
  cv::Mat to_gray(const cv::Mat& image) const;
  /// Re-detects keypoints at pose_i1_, adds the time to result.times; returns it, ms.
  /// `same_frame_as_track`: `gray` went through keypoints_.track() in this call.
  double detect_keypoints(const cv::Mat& gray, TrackResult& result,
                          bool same_frame_as_track = false);
  /// (Re)creates or drops the motion model for params_.motion_model.
  void configure_motion_model();
  /// (Re)creates the refiner's region and motion-prior cues for params_ (coarse_to_fine only).
  void configure_cues();
  /// The frame in colour, undistorted like to_gray(); empty for a grey frame.
  cv::Mat to_bgr(const cv::Mat& image) const;
  /// Pose expected in the next frame: the motion model's prediction, else the last pose.
  Pose predicted_pose() const;
  /// (Re)makes the simplified mesh's refiner for hypothesis_mesh_error_diameters (none at 0).
  void configure_coarse_refiner();

  std::shared_ptr<const Mesh> mesh_;
  PinholeCamera camera_;
  TrackerParams params_;
  KeypointTracker keypoints_;
  std::unique_ptr<PoseRefiner> refiner_;
  /// refine_hypotheses()' second thread's refiner (a replica of refiner_), made when needed.
  std::unique_ptr<PoseRefiner> hypothesis_refiner_;
  /// hypothesis_mesh_error_diameters > 0: the mesh simplified within it (and that error) and the
  /// hypotheses' refiner on it, built at start and on set_params() (configure_coarse_refiner());
  /// the second thread's replica of it when first needed.
  std::shared_ptr<const Mesh> coarse_mesh_;
  double coarse_mesh_error_diameters_ = 0.0;
  std::unique_ptr<PoseRefiner> coarse_refiner_, coarse_refiner_odd_;
  std::unique_ptr<MotionModel> motion_;  ///< null unless params_.motion_model
  std::shared_ptr<RegionCost> region_cost_;       ///< null unless region_weight > 0
  std::shared_ptr<MotionPriorCost> motion_prior_;  ///< null unless motion_prior_weight > 0
  /// params_.num_threads threads (the caller's included), persistent: see worker_threads.h.
  std::unique_ptr<WorkerThreads> workers_;
  cv::Mat undistort_map_x_, undistort_map_y_;
  double diameter_m_ = 0.0;                         ///< mesh diameter, metres
  Eigen::Vector3d center_object_ = Eigen::Vector3d::Zero();  ///< bounding-box centre, object frame
  State state_ = State::kWaiting;
  Pose pose_i1_ = Pose::Identity();  ///< pose of the previous frame
  Pose pose_i2_ = Pose::Identity();  ///< pose of the frame before
  int frames_since_init_ = 0;
  int frames_since_detection_ = 0;
  /// occlusion_mask_radius_px: the anchors whose track failed on each of the last
  /// occlusion_mask_frames frames (frames_since_init_ of that frame, object-frame points).
  std::vector<std::pair<int, std::vector<Eigen::Vector3d>>> occluded_anchors_;
  /// Remembers this frame's failed anchors (unless most tracks failed) and returns the mask of
  /// the remembered ones at `object_to_camera` (empty when off or none).
  cv::Mat update_occlusion_mask(const KeypointResult& keypoints, const Pose& object_to_camera);
};

}  // namespace kct
