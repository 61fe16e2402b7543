#pragma once
/// \file track_quality.h
/// Per-frame tracking quality and the WAITING_FOR_POSE / TRACKING / LOST state machine (ours;
/// the paper has no failure detection). A frame's quality mixes two cues the pipeline already
/// computes: the contour energy at the final pose (Eq. 5) relative to its running level over
/// recent good frames, and the KLT RANSAC inlier ratio. The monitor only classifies results;
/// the caller decides what to do (e.g. Tracker::reacquire() while lost).

#include <limits>
#include <string>

#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/tracker.h"

namespace kct {

/// Tracking state of one object.
enum class TrackState {
  kWaitingForPose,  ///< no pose given yet (or reset): nothing is tracked
  kTracking,        ///< the track is good (or has been bad for fewer than lost_after_bad_frames)
  kLost,            ///< lost_after_bad_frames bad frames in a row; re-acquiring
};
/// "waiting_for_pose", "tracking", "lost".
const char* to_string(TrackState state);

/// Colour evidence of a frame's pose (ObjectSearch::score()), when the session has a colour model.
struct ColorEvidence {
  bool valid = false;             ///< false: no colour model or a grey frame (ignored)
  double contrast = 0.0;          ///< mean P(fg) inside the silhouette - in a ring around it
  double visible_fraction = 1.0;  ///< share of the silhouette inside the image
  /// Correlation of the pose's surface colours with the learned ones (SurfaceTexture), NaN when
  /// not scored or the object has no colour pattern. Used by ColorLossRule::surface_hold_correlation,
  /// also when `valid` is false.
  double surface_correlation = std::numeric_limits<double>::quiet_NaN();
};

/// When colour evidence makes a frame bad, or a bad frame is held, and when a run of
/// extrapolated frames does (TrackingSession fills each field from the TrackerParams field of
/// its name prefixed color_, e.g. color_lost_ratio, and surface_hold_correlation and
/// extrapolated_good_frames from the fields of those names; outside_trusted_depth per frame).
struct ColorLossRule {
  /// A frame is faded (bad) when its contrast is below this x the running level (0 = never).
  double lost_ratio = 0.0;
  /// 0 = off. A faded frame stays good while its refined contour energy is at least this x the
  /// running energy level (the outline still lies on the object's edges: light, a shadow or a
  /// newly seen side changed the colours, not the pose) ...
  double contour_veto_ratio = 0.0;
  /// 0 = off. A faded frame also stays good when KLT kept at least this many RANSAC inliers at
  /// an inlier ratio >= keypoint_veto_inlier_ratio (a flash or a moving light changes the
  /// colours and the edges at once, while the keypoints, matched on locally normalized
  /// frames, still agree), ...
  int keypoint_veto_inliers = 0;
  double keypoint_veto_inlier_ratio = 0.95;  ///< see keypoint_veto_inliers
  /// ... unless (either veto) its contrast is below this x the colour level (the outline's
  /// inside has lost the object's colours: it lies on the background).
  double vanished_ratio = 0.0;
  /// 0 = off. While LOST, a frame counts towards recovery only when its contrast is at least
  /// this x the colour level (no veto applies: a static distractor keeps its outline and its
  /// keypoints as well as the object does) ...
  double recover_ratio = 0.0;
  /// ... and at least this share of its silhouette is inside the image (0 = off): a pose mostly
  /// outside the image has too little outline and colour to be told from a distractor.
  double recover_min_visible = 0.0;
  /// 0 = off. While TRACKING, a bad frame that KLT tracked or extrapolated whose
  /// surface_correlation is at least this is held: neither counted towards the loss nor good
  /// (blur lowers the contour energy and the keypoints while the printed surface still matches).
  double surface_hold_correlation = 0.0;
  /// 0 = off. While LOST, a frame whose surface_correlation (when scored) is below this does not
  /// count towards recovery: the surface's own pattern is not where the pose puts it.
  double recover_min_surface_correlation = 0.0;
  /// -1 = off. At most this many results in a row with status kExtrapolated (KLT failed) can be
  /// good; later ones are bad (quality capped at min_quality / 2) until a result that is not
  /// extrapolated. Not a colour rule: it applies with or without colour evidence.
  int extrapolated_good_frames = -1;
  /// This frame's pose lies outside the depth range the session trusts (TrackerParams::
  /// trusted_depth_ratio): the frame is bad whatever its score.
  bool outside_trusted_depth = false;
};

/// Thresholds of the quality score and the state machine (all ours).
struct TrackQualityParams {
  /// Weight of the energy cue in the score when the refinement ran; the KLT inlier ratio gets
  /// 1 - energy_weight. Without refinement (klt_only) the score is the inlier ratio alone.
  double energy_weight = 0.7;
  /// A frame is good when its score is at least this, [0, 1].
  double min_quality = 0.5;
  /// Exponential-moving-average factor of the energy level over good frames, (0, 1].
  double energy_level_smoothing = 0.1;
  /// TRACKING -> LOST after this many consecutive bad frames.
  int lost_after_bad_frames = 3;
  /// LOST -> TRACKING after this many consecutive good frames.
  int recover_after_good_frames = 3;
  /// While lost, the extrapolated search box (Sec. 3.4) is scaled by this for re-acquisition.
  double reacquire_search_scale = 2.0;

  /// Throws std::invalid_argument naming the first bad field and its allowed range.
  void validate() const;
};

/// Sets one field of `params` by name from text, as the nodelet's parameters of the same names
/// (energy_weight, min_quality, energy_level_smoothing, lost_after_bad_frames,
/// recover_after_good_frames, reacquire_search_scale) set it: the offline tools take the same
/// settings. Throws std::invalid_argument for an unknown name or a value that is not a number
/// (whole for the frame counts); the range is checked by validate().
void set_quality_param(TrackQualityParams& params, const std::string& name, const std::string& value);

/// Scores TrackResults and runs the state machine. Transitions:
/// WAITING_FOR_POSE -> TRACKING on on_initialized(); TRACKING -> LOST after
/// lost_after_bad_frames bad frames in a row; LOST -> TRACKING after recover_after_good_frames
/// good frames in a row; any state -> WAITING_FOR_POSE on reset() or a kNotInitialized result.
/// kInvalidInput results change nothing.
class TrackQualityMonitor {
 public:
  /// Throws std::invalid_argument if the parameters do not validate.
  explicit TrackQualityMonitor(const TrackQualityParams& params = {});

  /// Quality of one result in [0, 1] given the current energy level (does not change state):
  /// e = clamp(energy_after / level, 0, 1) (1 while no level is known yet), k = KLT inlier ratio
  /// (0 when KLT failed); score = energy_weight * e + (1 - energy_weight) * k if refined, else k.
  /// kInitialized and kReacquired-without-refinement results score 1 (the pose was given).
  double score(const TrackResult& result) const;

  /// Scores `result`, updates the energy level (good frames only), the last good pose and the
  /// state. Returns the new state. With valid `color` evidence a frame is also bad when less
  /// than 10 % of the object is in the image or its contrast is below `rule.lost_ratio` x the
  /// running contrast level of good frames (`rule`: when the contour energy or KLT overrules that).
  /// A bad tracked frame whose surface colours still match (`rule.surface_hold_correlation`) is
  /// held: the state, the counters and the levels do not change. While LOST, a frame that
  /// `repeats_previous_find` (the session's repeat_recover_diameters: re-acquired where the
  /// previous frame was) is good whatever its score; the colour rules above still apply.
  TrackState update(const TrackResult& result, const ColorEvidence& color = {},
                    const ColorLossRule& rule = {}, bool repeats_previous_find = false);
  /// Running colour contrast of good frames (0 when none yet).
  double color_level() const { return color_level_; }
  /// Colour evidence counts only once the running contrast is at least this: a model whose
  /// outline separates the colours less at good poses tells too little to judge a frame by.
  static constexpr double kMinColorLevel = 0.2;

  /// A pose was given to the tracker: TRACKING, counters cleared, the energy level forgotten.
  void on_initialized(const Pose& object_to_camera);
  /// The track was dropped: WAITING_FOR_POSE.
  void reset();

  TrackState state() const { return state_; }
  /// True while LOST and the last frame was bad: the caller should re-acquire around
  /// last_good_pose() instead of tracking from the last (bad) pose.
  bool should_reacquire() const { return state_ == TrackState::kLost && good_frames_ == 0; }
  /// Score of the last update() (0 before any).
  double last_quality() const { return last_quality_; }
  /// Whether the last update() was a good frame.
  bool last_good() const { return last_good_; }
  /// Whether the last update() was a bad frame held by ColorLossRule::surface_hold_correlation
  /// (not counted towards the loss).
  bool last_held() const { return last_held_; }
  /// Pose of the last good frame (or the last given pose), object_to_camera.
  const Pose& last_good_pose() const { return last_good_pose_; }
  /// Running contour-energy level of good refined frames (0 when none yet).
  double energy_level() const { return energy_level_; }
  int consecutive_bad_frames() const { return bad_frames_; }
  int consecutive_good_frames() const { return good_frames_; }
  const TrackQualityParams& params() const { return params_; }
  /// Validates and replaces the thresholds; keeps the state.
  void set_params(const TrackQualityParams& params);

 private:
  TrackQualityParams params_;
  TrackState state_ = TrackState::kWaitingForPose;
  Pose last_good_pose_ = Pose::Identity();
  double energy_level_ = 0.0;
  bool has_energy_level_ = false;
  double color_level_ = 0.0;
  bool has_color_level_ = false;
  double last_quality_ = 0.0;
  bool last_good_ = false;
  bool last_held_ = false;
  int bad_frames_ = 0;
  int good_frames_ = 0;
  int extrapolated_frames_ = 0;  ///< results in a row with status kExtrapolated
};

}  // namespace kct
