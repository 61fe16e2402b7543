#pragma once
/// \file tracking_session.h
/// One tracking session, the same for every front end (nodelet, track_sequence, benchmark,
/// demo): the per-frame pipeline (Tracker), the quality monitor and its TRACKING / LOST state
/// machine (TrackQualityMonitor), re-acquisition while lost, and a restart from a given pose
/// when time jumps backwards (a looping bag), behind one track() call. Ours; the paper has no
/// failure handling. The session owns no thread and does no I/O.

#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/feature_relocalizer.h"
#include "klt_contour_tracker/core/object_search.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/surface_texture.h"
#include "klt_contour_tracker/core/track_quality.h"
#include "klt_contour_tracker/core/tracker.h"
#include "klt_contour_tracker/core/tracker_params.h"

namespace kct {

/// One hypothesis a colour search refined on a frame (TrackingSession::set_record_hypotheses):
/// what the re-acquisition had to choose from, for measuring how far its hypotheses reach.
struct HypothesisRecord {
  Pose start_object_to_camera = Pose::Identity();  ///< where its refinement started, metres
  Pose object_to_camera = Pose::Identity();        ///< the refined pose, metres
  double contrast = 0.0;        ///< colour contrast of the refined pose (ObjectSearch::score)
  double energy = 0.0;          ///< contour energy after the refinement
  bool in_reach = true;         ///< within color_search_reach_diameters (only those can win)
  bool chosen = false;          ///< the search's best: the pose it takes if it passes its bar
  /// A search of a frame that re-acquires (SessionResult::reacquiring), not a check of a
  /// tracked pose (extrapolated_search_ratio / tracked_search_ratio).
  bool reacquiring = false;
  /// Its surface colours' correlation with the learned ones (SurfaceTexture::agreement; objects
  /// with a colour pattern): NaN when not scored (no pattern, fewer than kMinPoints points).
  double surface_correlation = std::numeric_limits<double>::quiet_NaN();
};

/// What one TrackingSession::track() call did.
struct SessionResult {
  /// The pipeline's result (poses in metres); its frame_time_ms is the wall time of the whole
  /// TrackingSession::track() call.
  TrackResult frame;
  TrackState previous_state = TrackState::kWaitingForPose;  ///< state before this frame
  TrackState state = TrackState::kWaitingForPose;      ///< state after this frame
  double quality = 0.0;      ///< the monitor's score in [0, 1]; 0 when the frame has no pose
  bool good = false;         ///< quality >= min_quality (and the frame has a pose)
  bool reacquiring = false;  ///< the frame ran re-acquisition instead of tracking
  /// The pose came from the colour search's best placement (color_search): a re-acquisition
  /// while lost, or a held track replaced by extrapolated_search_ratio / tracked_search_ratio.
  bool searched = false;
  /// The pose came from the feature relocalizer (feature_relocalization): a re-acquisition
  /// while lost, or a held track it replaced.
  bool relocalized = false;
  /// rotation_check replaced the tracked pose by a turned one that the colours fit better.
  bool rotation_corrected = false;
  /// texture_check replaced the tracked pose by one turned about an object axis whose surface
  /// colours match the learned ones better.
  bool texture_corrected = false;
  /// texture_check's correlation of the held pose's surface colours with the learned ones
  /// (SurfaceTexture::agreement), in [-1, 1], or the corrected pose's when the check replaced
  /// it; NaN when the check did not run on this frame or fewer than SurfaceTexture::kMinPoints
  /// learned points face the camera there.
  double texture_correlation = std::numeric_limits<double>::quiet_NaN();
  ColorEvidence color;       ///< colour evidence of the pose (valid with color_search)
  /// With set_record_hypotheses(true): every hypothesis the colour searches of this frame
  /// refined, in their order (a frame can be searched twice); empty otherwise.
  std::vector<HypothesisRecord> hypotheses;
  bool time_jumped_back = false;  ///< the frame's stamp is earlier than the previous frame's
  bool restarted = false;    ///< ... and the session restarted from restart_pose()
  /// True unless the status is kNotInitialized or kInvalidInput.
  bool has_pose() const;
  /// The state changed on this frame.
  bool state_changed() const { return state != previous_state; }
};

/// Counters of a session since its construction or the last clear_statistics().
struct SessionStatistics {
  int frames = 0;          ///< frames passed to track()
  int invalid_frames = 0;  ///< frames rejected as kInvalidInput
  int frames_lost = 0;     ///< frames that ended in state LOST
  int losses = 0;          ///< TRACKING -> LOST transitions
  int reacquisitions = 0;  ///< LOST -> TRACKING transitions
  int restarts = 0;        ///< restarts from restart_pose() on a backward time jump
  /// For each re-acquisition: frames from the one that declared the loss to the one that
  /// declared the track good again (>= recover_after_good_frames).
  std::vector<int> frames_to_reacquire;
};

/// What the session's colour search must reach for its best hypothesis to replace a held pose
/// (tracked_search_ratio); the defaults ask nothing.
struct SearchBar {
  double min_contrast = -std::numeric_limits<double>::infinity();  ///< colour contrast
  double min_energy = -std::numeric_limits<double>::infinity();    ///< refined contour energy
  /// A find at least this contrast is taken even below color_accept_ratio x the level (+inf:
  /// only the accept ratio or a two-frame confirmation take it).
  double accept_contrast = std::numeric_limits<double>::infinity();
  /// A find whose surface colours (texture_check's learned pattern) correlate below this is not
  /// taken (-inf: not asked).
  double min_surface_correlation = -std::numeric_limits<double>::infinity();
};

/// Tracks one rigid object in one camera's stream with loss detection and re-acquisition.
/// Poses are object_to_camera, metres.
class TrackingSession {
 public:
  /// Throws std::invalid_argument for an empty mesh or parameters that do not validate.
  TrackingSession(std::shared_ptr<const Mesh> mesh, const TrackerParams& params,
                  const TrackQualityParams& quality = {});
  ~TrackingSession();

  /// Sets the intrinsics: the first call creates the tracker (building or loading its
  /// visibility table), later ones keep the track. Throws std::invalid_argument for a camera
  /// without image size.
  void set_camera(const PinholeCamera& camera);
  bool has_camera() const { return tracker_ != nullptr; }

  /// The next frame has this pose; TRACKING from it. Throws std::invalid_argument for an invalid
  /// pose or one behind the camera, std::logic_error before set_camera().
  void initialize(const Pose& object_to_camera);
  /// Drops the track: WAITING_FOR_POSE until initialize(). Keeps the restart pose.
  void reset();
  /// Pose re-applied when a frame's stamp is earlier than the previous frame's while a track
  /// is held (a looping bag restarts where the operator started it); none = keep tracking.
  void set_restart_pose(const std::optional<Pose>& object_to_camera) { restart_pose_ = object_to_camera; }
  const std::optional<Pose>& restart_pose() const { return restart_pose_; }
  /// True when a frame stamped `stamp_s` would be a backward time jump.
  bool time_jumps_back(double stamp_s) const { return has_last_stamp_ && stamp_s < last_stamp_s_; }

  /// One frame: restart on a backward time jump (when a restart pose is set and no pose was
  /// given since the last frame), then the pipeline, or re-acquisition while LOST and the last
  /// frame was bad; then the monitor's verdict. Before set_camera() the result is
  /// kNotInitialized. Exceptions of the pipeline (e.g. a failing OpenCV call) propagate.
  SessionResult track(const Frame& frame);

  TrackState state() const { return monitor_.state(); }
  const TrackQualityMonitor& monitor() const { return monitor_; }
  /// The pipeline; std::logic_error before set_camera().
  const Tracker& tracker() const;
  const Mesh& mesh() const { return *mesh_; }
  const TrackerParams& params() const { return params_; }
  /// The track's learned surface shows no colour pattern (plain_surface_keypoint_scale applies
  /// to it); false before a colour frame was learned at the initial pose.
  bool plain_surface() const { return plain_surface_; }
  const TrackQualityParams& quality_params() const { return monitor_.params(); }
  /// Validate and replace the parameters (std::invalid_argument); keep the track.
  void set_params(const TrackerParams& params);
  void set_quality_params(const TrackQualityParams& quality);
  /// Report the colour searches' refined hypotheses in SessionResult::hypotheses (a
  /// measurement aid: track_sequence --hypotheses; the tracking itself does not change).
  void set_record_hypotheses(bool record) { record_hypotheses_ = record; }
  /// A measurement aid (track_sequence --truth-refinement): `start` refined on `frame` (the
  /// frame track() was just given) as a re-acquisition hypothesis is refined there: the
  /// contour refinement alone, without keypoints or the shift search. From the true pose it
  /// shows whether the refinement's objective holds the truth. The track does not change (only
  /// the refiner's per-call state is used). An invalid result (status kInvalidInput or
  /// kNotInitialized) when there is no camera or track yet, or the frame is unusable.
  TrackResult refine_from(const Frame& frame, const Pose& start);

  const SessionStatistics& statistics() const { return statistics_; }
  void clear_statistics() { statistics_ = {}; }

 private:
  /// The colour model, its searches on params_.num_threads threads.
  std::unique_ptr<ObjectSearch> make_search() const;
  /// Re-acquisition while lost: the colour search's hypotheses, else (not `color_only`) a
  /// refinement around the last good pose, or with track_while_lost the pipeline's frame from
  /// where the last frame ended. `color_only` and nothing found (or nothing above `bar`): a
  /// default result (searched false).
  TrackResult reacquire(const Frame& frame, const cv::Mat& bgr, bool& searched,
                        bool color_only = false, const SearchBar& bar = SearchBar());
  /// color_search_reach_diameters: how far (full-resolution px) from the last good pose's
  /// projected centre the object can be on this frame; 0 = anywhere.
  double search_reach_px() const;
  /// True when `object_to_camera`'s centre projects within `reach_px` (a search_reach_px()) of
  /// the last good pose's; always when `reach_px` is 0.
  bool within_reach(const Pose& object_to_camera, double reach_px) const;
  /// True when `b`'s object centre is within `diameters` x the object's diameter of `a`'s and
  /// the rotation between them is below `deg`.
  bool same_place(const Pose& a, const Pose& b, double diameters, double deg) const;
  /// texture_shift_search_below, from texture_check (the held pose's colours `prepared`,
  /// correlating at `held_correlation`): true when a confirmed shift replaced the held pose.
  bool shift_by_texture(const Frame& frame, const cv::Mat& bgr, const PreparedFrame& prepared,
                        double held_correlation, SessionResult& result);
  /// texture_align_below, from texture_check (as shift_by_texture()): true when the aligned
  /// pose replaced the held one.
  bool align_by_texture(const Frame& frame, const cv::Mat& bgr, const PreparedFrame& prepared,
                        double held_correlation, SessionResult& result);
  /// shift_by_texture() and align_by_texture(): `found` refined (contour only; with the
  /// shift search or not) replaces the held pose in `result` when the refined pose's colours
  /// still correlate at least `needed` with the surface in `prepared`, it keeps 0.9 of the held
  /// contour energy and passes color_accept_ratio. True when it did.
  bool take_if_surface_agrees(const Frame& frame, const cv::Mat& bgr, const PreparedFrame& prepared,
                              const Pose& found, double needed, bool shift_search,
                              SessionResult& result);
  void count(const SessionResult& result);
  /// feature_relocalization, on a frame the pipeline tracked (`gray` undistorted): the
  /// keyframes' features around the held pose confirm it, or replace it when they disagree
  /// and the track is in doubt (KLT failed, the last frame was bad, or `in_doubt`: the
  /// surface disagrees; then, with relocalization_doubt_whole_frame, over the whole frame
  /// when nothing was found around it).
  void use_features(const Frame& frame, const cv::Mat& gray, SessionResult& result,
                    bool in_doubt = false);
  /// relocalization_below_correlation: the tracked frame `result`'s surface (a colour
  /// pattern's) does not correlate with the learned one.
  bool surface_disagrees(const SessionResult& result) const;
  /// feature_relocalization, while lost: the keyframes' features over the whole frame; true
  /// when they re-acquired the object (`result` then holds it).
  bool relocalize(const Frame& frame, const cv::Mat& gray, SessionResult& result);
  /// The tracker continues from the relocalizer's `object_to_camera`; `result` reports it
  /// (kReacquired, relocalized).
  void adopt_relocalized(const Frame& frame, const Pose& object_to_camera, SessionResult& result);
  /// params_ as the tracker gets them: keypoint_weight scaled for a plain surface.
  TrackerParams tracker_params() const;
  /// Records whether the track's surface is plain and gives the tracker its params again when
  /// that changes their keypoint weight.
  void set_plain_surface(bool plain);
  /// extrapolated_search_ratio (a frame where KLT failed) and tracked_search_ratio (a frame KLT
  /// tracked): when the held pose's colour contrast is below `ratio` x its level, the frame is
  /// searched for the object at once. `must_beat_held`: the find replaces the held pose only
  /// when it beats it (see TrackerParams::tracked_search_ratio).
  void search_if_faded(const Frame& frame, const cv::Mat& bgr, SessionResult& result,
                       double ratio, bool must_beat_held);
  /// rotation_check's and texture_check's common ground: the colour model is ready, the frame
  /// is in colour and `held` is a refined tracked pose (kKeypoints, kExtrapolated).
  bool checkable(const TrackResult& held, const cv::Mat& bgr) const;
  /// rotation_check: the tracked pose turned by +-rotation_check_deg about camera axes, each
  /// refined; one whose colour contrast beats the held pose's by the margin (and whose contour
  /// energy is no lower) replaces it and the keypoints are anchored afresh.
  void check_rotation(const Frame& frame, const cv::Mat& bgr, SessionResult& result);
  /// texture_check: the tracked pose turned about the object's own axes; a turn whose surface
  /// colours match the learned ones better by the margin, on two consecutive frames, is refined
  /// and replaces the held pose (see TrackerParams::texture_check_margin).
  void check_texture(const Frame& frame, const cv::Mat& bgr, SessionResult& result);
  /// Adds a keyframe on the initial frame and on confident frames seen from a new viewpoint.
  void add_keyframe_if_due(const cv::Mat& gray, const SessionResult& result);
  /// The colour model's evidence for `result` and its learning on good frames (color_search).
  void use_colors(const cv::Mat& bgr, SessionResult& result);

  std::shared_ptr<const Mesh> mesh_;
  TrackerParams params_;
  TrackQualityMonitor monitor_;
  std::unique_ptr<Tracker> tracker_;
  std::unique_ptr<ObjectSearch> search_;  ///< the colour model; null unless color_search
  /// Keyframe features; null unless feature_relocalization.
  std::unique_ptr<FeatureRelocalizer> relocalizer_;
  /// This frame's held pose was confirmed by the keyframes' features (a new keyframe is added
  /// only on such a frame, so that a wrong track never becomes a keyframe).
  bool features_confirm_ = false;
  int frames_since_learning_ = 0;
  int rotation_check_winner_ = -1;  ///< the turn that won rotation_check on the last frame
  /// The surface colours learned at the initial pose; null unless texture_check_margin > 0.
  std::unique_ptr<SurfaceTexture> texture_;
  int texture_check_winner_ = -1;  ///< the turn that won texture_check on the last frame
  /// texture_shift_search_below: the shift found on the last frame it searched, if any.
  std::optional<Eigen::Vector3d> texture_shift_winner_m_;
  int frames_since_doubt_ = 1000;  ///< frames since KLT last failed or a re-acquisition
  int reacquiring_frames_ = 0;     ///< frames in a row that re-acquired (relocalization_interval_frames)
  /// trusted_depth_ratio: depth (m) of the object's centre at the last trusted pose, and the
  /// good TRACKING frames since the last re-acquisition (trusted from kTrustAfterFrames on).
  double trusted_depth_m_ = 0.0;
  int frames_since_recovery_ = 0;
  /// The colour search's reference pose: the last good pose, its centre moved along its viewing
  /// ray into the trusted depth range (trusted_depth_ratio; unchanged when off).
  Pose search_reference() const;
  /// color_search_refined: of hypotheses[first_placed..] (the colour placements and their
  /// turns), keeps the color_search_refined with the best colour contrast in `bgr`, in order.
  void keep_best_placements(const cv::Mat& bgr, std::size_t first_placed,
                            std::vector<Pose>& hypotheses);
  /// Depth (m, along the camera axis) of the object's centre at `object_to_camera`.
  double center_depth_m(const Pose& object_to_camera) const;
  /// trusted_depth_ratio: `object_to_camera`'s centre lies outside the trusted depth range.
  bool outside_trusted_depth(const Pose& object_to_camera) const;
  std::optional<Pose> restart_pose_;
  bool initialized_since_last_frame_ = false;
  bool has_last_stamp_ = false;
  double last_stamp_s_ = 0.0;
  int lost_at_frame_ = -1;  ///< statistics_.frames when the current loss was declared
  bool plain_surface_ = false;  ///< see plain_surface()
  /// The previous frame's best re-acquisition hypothesis above color_confirm_ratio, if any.
  std::optional<Pose> unconfirmed_;
  /// This frame's colour search and refined re-acquisition hypotheses. With track_while_lost a
  /// lost frame can be searched twice (reacquire(), then search_if_faded() on the frame it
  /// tracked on): the second pass takes the first's placements and refinements instead of
  /// computing them again (the same frame, last good pose and reach; a refinement depends only
  /// on its start and the frame).
  struct FrameSearch {
    bool searched = false;
    std::vector<SearchCandidate> found;  ///< ObjectSearch::search(), before any cut
    std::vector<Pose> starts;            ///< refined hypotheses ...
    std::vector<TrackResult> refined;    ///< ... and their refinements
    std::vector<Pose> scored;             ///< poses whose colours were scored ...
    std::vector<SearchCandidate> scores;  ///< ... and their scores
  };
  FrameSearch frame_search_;
  bool record_hypotheses_ = false;                 ///< see set_record_hypotheses()
  std::vector<HypothesisRecord> frame_hypotheses_;  ///< this frame's, when recorded
  /// While LOST, the previous frame's re-acquired pose (repeat_recover_diameters), if it was one.
  std::optional<Pose> previous_find_;
  /// repeat_recover_diameters: whether `result` (this frame's) was re-acquired where the previous
  /// frame was; remembers it for the next frame.
  bool repeats_previous_find(const SessionResult& result);
  /// reacquire()'s refinement of `hypotheses` (search scale 1), from frame_search_ where a
  /// start was refined on this frame already.
  std::vector<TrackResult> refine_once(const Frame& frame, const std::vector<Pose>& hypotheses);
  /// ObjectSearch::score() of `poses` on this frame, from frame_search_ where a pose was scored
  /// on this frame already (a lost frame scores its placements and refined hypotheses again
  /// when the pipeline's extrapolated pose is searched from: a pure function of the frame, the
  /// pose and the colour model, which is learned only after the frame's checks).
  std::vector<SearchCandidate> score_once(const cv::Mat& bgr, const std::vector<Pose>& poses);
  SearchCandidate score_once(const cv::Mat& bgr, const Pose& pose) {
    return score_once(bgr, std::vector<Pose>{pose}).front();
  }
  SessionStatistics statistics_;
};

}  // namespace kct
