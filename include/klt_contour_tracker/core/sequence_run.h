#pragma once
/// \file sequence_run.h
/// Tracking a sequence folder (sequence_io.h) offline with a TrackingSession, and scoring it
/// with the paper's metric (Sec. 4.1). What the track_sequence tool (and through it the
/// benchmark) runs, here in the core so that it is tested as it is used.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/sequence_io.h"
#include "klt_contour_tracker/core/track_quality.h"
#include "klt_contour_tracker/core/tracker_params.h"
#include "klt_contour_tracker/core/tracking_session.h"

namespace kct {

/// Options of track_sequence_folder().
struct SequenceRunOptions {
  std::size_t max_frames = 0;  ///< frames tracked from the start; 0 = all
  /// Largest frame accepted, in pixels (width x height), read from the file header before any
  /// pixel is decoded: a frame beyond it is refused with a per-frame error. 16 Mpx (4096 x 4096)
  /// = 48 MB decoded as BGR.
  std::int64_t max_image_pixels = std::int64_t{4096} * 4096;
  TrackQualityParams quality;  ///< loss detection / re-acquisition thresholds
  /// > 0: a live camera at this rate, Hz. Frame i arrives at i / camera_rate_hz s; the session
  /// takes each frame as long as its track() call takes here (wall time), and a frame that a
  /// newer one has replaced by the time the session is free is dropped, as a live stream with a
  /// one-message queue drops it (the nodelet's default ~queue_size 1). A dropped frame keeps the
  /// last pose (what the robot holds then) and is not passed to on_frame. 0: every frame is
  /// tracked, however long it takes (a bag played paced on the tracker).
  double camera_rate_hz = 0.0;
  /// Called after every frame: its index, the decoded image (empty when the frame could not be
  /// read), the session's result and the session.
  std::function<void(std::size_t, const cv::Mat&, const SessionResult&, const TrackingSession&)> on_frame;
  /// TrackingSession::set_record_hypotheses: on_frame's results list the colour searches'
  /// refined hypotheses.
  bool record_hypotheses = false;
  /// A measurement aid: after each tracked frame with ground truth (sequence.poses[i], i >= 1
  /// and more than one pose), its true pose refined by TrackingSession::refine_from() into
  /// SequenceRun::truth_refined (does the refinement's objective hold the truth?). The track
  /// does not change; the time is not counted in the frame's.
  bool refine_truth = false;
};

/// Outcome of track_sequence_folder().
struct SequenceRun {
  /// One estimate per frame, object_to_camera, metres. A frame that could not be used gets the
  /// previous estimate.
  std::vector<Pose> object_to_camera;
  std::vector<double> frame_ms;           ///< Tracker time of each frame after the first
  std::vector<std::string> frame_errors;  ///< "file: reason" of each frame that could not be used
  int extrapolated = 0;                   ///< frames whose preliminary pose was extrapolated
  /// camera_rate_hz: per frame, 1 when it was dropped (never tracked; it holds the last pose).
  std::vector<char> dropped;
  int dropped_frames = 0;                 ///< frames dropped at camera_rate_hz
  SessionStatistics statistics;           ///< losses, re-acquisitions... of the session
  /// Wall time of the session's start (its tracker and visibility table: built, or read from
  /// the cache), ms; what a nodelet spends before its first frame.
  double startup_ms = 0.0;
  PinholeCamera camera;                   ///< from K.txt and the first frame's size
  /// refine_truth: per frame, the true pose refined (status kNotInitialized where it was not:
  /// no ground truth, the first frame, a dropped or unusable frame).
  std::vector<TrackResult> truth_refined;
};

/// Tracks `sequence` (poses in metres: read_sequence() converted them) from its first pose with
/// a TrackingSession. Frames are checked against the first frame's size and
/// options.max_image_pixels from their headers before decoding. Throws std::runtime_error when
/// the sequence has no pose or its first frame cannot be used, std::invalid_argument for bad
/// parameters.
SequenceRun track_sequence_folder(const SequenceFolder& sequence, std::shared_ptr<const Mesh> mesh,
                                  const TrackerParams& params, const SequenceRunOptions& options = {});

/// The paper's scores (Sec. 4.1) of estimates against ground truth, both object_to_camera in
/// metres, over the first min(estimated, truth) frames.
struct SequenceScore {
  std::size_t scored_frames = 0;
  std::vector<double> errors_m;  ///< delta_i per scored frame (mean vertex distance), metres
  double auc = 0.0;              ///< area under the success curve, k in [0, 0.2], of 20
  double success_5cm5deg = 0.0;  ///< fraction within 5 cm and 5 deg
  double mean_add_m = 0.0;       ///< mean of errors_m
  double diameter_m = 0.0;       ///< the mesh's diameter d
};

/// Scores estimates against truth. Throws std::invalid_argument when fewer than 2 frames have
/// both (the first frame is the given pose: nothing would be measured), saying how many.
SequenceScore score_sequence(const Mesh& mesh, const std::vector<Pose>& estimated_m,
                             const std::vector<Pose>& truth_m);

}  // namespace kct
