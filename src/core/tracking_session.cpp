#include "klt_contour_tracker/core/tracking_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "klt_contour_tracker/core/elapsed.h"

namespace kct {
namespace {

/// feature_relocalization: a keyframe is added on a good frame with at least this quality and
/// KLT inlier ratio, from a new viewpoint, whose pose the existing keyframes confirmed.
constexpr double kKeyframeMinQuality = 0.8;
constexpr double kKeyframeMinInlierRatio = 0.8;
/// feature_relocalization: features are matched within this share of the object's projected
/// size around the held pose.
constexpr double kRegionMargin = 0.5;
/// feature_relocalization: the relocalized pose agrees with the held one when their centres are
/// less than this many diameters apart and their rotations less than this many degrees.
constexpr double kAgreementDiameters = 0.05;
constexpr double kAgreementDeg = 5.0;
/// rotation_check corrects the rotation: a turned hypothesis whose refined centre moved farther
/// than this many diameters from the held one is not considered.
constexpr double kRotationCheckMaxShiftDiameters = 0.2;
/// texture_check: a turn must correlate at least this well with the learned surface colours
/// (weaker matches are as often a wrong turn as a right one).
constexpr double kTextureCheckMinCorrelation = 0.5;
/// texture_shift_search_below: the grid of shifts (lateral step and count each way, in
/// diameters; depth step, share of the depth) and how far two frames' shifts may differ to
/// confirm each other (diameters).
constexpr double kShiftStepDiameters = 0.05;
constexpr int kShiftSteps = 5;
constexpr double kShiftDepthStep = 0.08;
constexpr double kShiftConfirmDiameters = 0.15;
/// tracked_search_ratio: the colour search's find replaces a KLT-tracked pose when its colour
/// contrast beats the held one's by this x the contrast level and its contour energy is at
/// least this share of the held one's and this share of the running energy level (a find with a
/// weak outline is as often a near miss as the object: photo/toy/light was held 2-3 cm off by
/// one instead of being declared lost and re-acquired within 0.3 cm).
constexpr double kTrackedSearchMargin = 0.2;
constexpr double kTrackedSearchMinEnergyRatio = 0.9;
constexpr double kTrackedSearchMinEnergyLevel = 0.7;
/// tracked_search_ratio: the search's hypotheses are refined only when its best placement's
/// contrast (before refinement) is within this x the contrast level of the bar. Measured over
/// the 584 tracked searches of both hard sets: refinement raised the best contrast over the best
/// placement's by 0.004 (median), 0.135 (99th percentile); of the 31 finds taken, none was
/// below its bar by more than 0.15 x the level before refinement, while 298 of the searches
/// were, each refining 23 hypotheses for nothing (the grey castle, whose colours stay faded,
/// searched on most frames at ~200 ms each).
constexpr double kTrackedSearchRefineSlack = 0.15;
/// tracked_search_surface_drop: the held pose's surface must correlate at least this well for
/// its find to be asked to (a weaker correlation does not say where the surface is).
constexpr double kSurfaceDropMinHeldCorrelation = 0.5;
/// texture_align_below: the alignment's bounds (turn about the centre, degrees; shift of the
/// centre, diameters) and its budget of agreements.
constexpr double kAlignMaxTurnDeg = 20.0;
constexpr double kAlignMaxShiftDiameters = 0.1;
constexpr int kAlignMaxEvaluations = 300;
/// texture_check: a refined turn keeps at least this share of the held pose's contour energy.
constexpr double kTextureCheckMinEnergyRatio = 0.9;
/// texture_check: an unrefined turn has the held pose's outline when its colour contrast is
/// lower by less than this x the contrast level.
constexpr double kSameOutlineContrastTolerance = 0.1;

/// trusted_depth_ratio: a re-acquired track's depth is trusted from its 30th good frame on (1 s
/// at 30 Hz: a wrong find is usually lost again sooner).
constexpr int kTrustAfterFrames = 30;

/// The colour evidence of a scored pose.
ColorEvidence evidence_of(const SearchCandidate& scored) {
  ColorEvidence evidence;
  evidence.valid = true;
  evidence.contrast = scored.contrast;
  evidence.visible_fraction = scored.visible_fraction;
  return evidence;
}

/// `pose` turned by +-angle_rad about each camera axis through the object's centre.
std::vector<Pose> turned_about_center(const Pose& pose, const Eigen::Vector3d& center_object,
                                      double angle_rad) {
  std::vector<Pose> turned;
  const Eigen::Vector3d center_camera = pose * center_object;
  for (int axis = 0; axis < 3; ++axis)
    for (const double sign : {-1.0, 1.0}) {
      Pose p = pose;
      p.linear() = Eigen::AngleAxisd(sign * angle_rad, Eigen::Vector3d::Unit(axis)) * pose.linear();
      p.translation() = center_camera - p.linear() * center_object;
      turned.push_back(p);
    }
  return turned;
}

/// A frame's memo of a batch computation on poses (refine_once, score_once): the values for
/// `poses`, from (keys, values) where a pose (exactly the same) was done on this frame already;
/// the others computed in one batch by `compute` and remembered when `keep` accepts them.
template <typename Value, typename Compute, typename Keep>
std::vector<Value> once_per_frame(const std::vector<Pose>& poses, std::vector<Pose>& keys,
                                  std::vector<Value>& values, const Compute& compute,
                                  const Keep& keep) {
  std::vector<Value> out(poses.size());
  std::vector<Pose> fresh;
  std::vector<std::size_t> fresh_index;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const auto same = std::find_if(keys.begin(), keys.end(), [&](const Pose& key) {
      return key.matrix() == poses[i].matrix();
    });
    if (same != keys.end()) {
      out[i] = values[static_cast<std::size_t>(same - keys.begin())];
    } else {
      fresh.push_back(poses[i]);
      fresh_index.push_back(i);
    }
  }
  if (fresh.empty()) return out;
  const std::vector<Value> done = compute(fresh);
  for (std::size_t k = 0; k < done.size(); ++k) {
    out[fresh_index[k]] = done[k];
    if (!keep(done[k])) continue;
    keys.push_back(fresh[k]);
    values.push_back(done[k]);
  }
  return out;
}

}  // namespace

bool SessionResult::has_pose() const {
  return frame.status != TrackStatus::kNotInitialized && frame.status != TrackStatus::kInvalidInput;
}

TrackingSession::TrackingSession(std::shared_ptr<const Mesh> mesh, const TrackerParams& params,
                                 const TrackQualityParams& quality)
    : mesh_(std::move(mesh)), params_(params), monitor_(quality) {
  if (!mesh_ || mesh_->faces.empty()) throw std::invalid_argument("TrackingSession: empty mesh");
  params_.validate();
}

TrackingSession::~TrackingSession() = default;

void TrackingSession::set_camera(const PinholeCamera& camera) {
  if (!tracker_)
    tracker_ = std::make_unique<Tracker>(mesh_, camera, tracker_params());
  else
    tracker_->set_camera(camera);
  if (params_.color_search && !search_) search_ = make_search();
  if (params_.feature_relocalization && !relocalizer_)
    relocalizer_ = std::make_unique<FeatureRelocalizer>(mesh_);
  if (params_.texture_check_margin > 0.0 && !texture_) texture_ = std::make_unique<SurfaceTexture>(mesh_);
}

std::unique_ptr<ObjectSearch> TrackingSession::make_search() const {
  ObjectSearchSettings settings;
  settings.threads = params_.num_threads;
  settings.silhouette_error_diameters = params_.color_search_mesh_error_diameters;
  return std::make_unique<ObjectSearch>(mesh_, settings);
}

const Tracker& TrackingSession::tracker() const {
  if (!tracker_) throw std::logic_error("TrackingSession: no camera yet (set_camera)");
  return *tracker_;
}

void TrackingSession::initialize(const Pose& object_to_camera) {
  if (!tracker_) throw std::logic_error("TrackingSession::initialize: no camera yet (set_camera)");
  tracker_->initialize(object_to_camera);  // validates the pose
  set_plain_surface(false);  // until the initial frame's surface is learned
  monitor_.on_initialized(object_to_camera);
  if (search_) search_->clear();  // a new track may be another scene
  if (relocalizer_) relocalizer_->clear();
  if (texture_) texture_->clear();
  texture_check_winner_ = -1;
  texture_shift_winner_m_.reset();
  frames_since_learning_ = 0;
  initialized_since_last_frame_ = true;
  lost_at_frame_ = -1;
  unconfirmed_.reset();
  rotation_check_winner_ = -1;
  frames_since_doubt_ = 1000;
  reacquiring_frames_ = 0;
  trusted_depth_m_ = center_depth_m(object_to_camera);
  frames_since_recovery_ = kTrustAfterFrames;
}

void TrackingSession::reset() {
  if (tracker_) tracker_->reset();
  monitor_.reset();
  initialized_since_last_frame_ = false;
  lost_at_frame_ = -1;
  unconfirmed_.reset();
}

void TrackingSession::set_params(const TrackerParams& params) {
  params.validate();
  params_ = params;
  if (tracker_) tracker_->set_params(tracker_params());
  if (!params_.feature_relocalization)
    relocalizer_.reset();
  else if (!relocalizer_ && tracker_)
    relocalizer_ = std::make_unique<FeatureRelocalizer>(mesh_);
  if (!params_.color_search)
    search_.reset();
  else if (!search_ && tracker_)
    search_ = make_search();
  else if (search_)
    search_->set_threads(params_.num_threads);
  if (!(params_.texture_check_margin > 0.0))
    texture_.reset();
  else if (!texture_ && tracker_)
    texture_ = std::make_unique<SurfaceTexture>(mesh_);
}

TrackerParams TrackingSession::tracker_params() const {
  TrackerParams params = params_;
  if (plain_surface_) params.keypoint_weight *= params_.plain_surface_keypoint_scale;
  if (params_.contour_chroma_plain_only && !plain_surface_) params.contour_chroma_weight = 0.0;
  return params;
}

void TrackingSession::set_plain_surface(bool plain) {
  if (plain == plain_surface_) return;
  plain_surface_ = plain;
  // Only the refiner's cue weights change (Tracker::set_params keeps the track).
  const bool changes = params_.plain_surface_keypoint_scale != 1.0 ||
                       (params_.contour_chroma_plain_only && params_.contour_chroma_weight > 0.0);
  if (tracker_ && changes) tracker_->set_params(tracker_params());
}

void TrackingSession::set_quality_params(const TrackQualityParams& quality) {
  monitor_.set_params(quality);
}

TrackResult TrackingSession::reacquire(const Frame& frame, const cv::Mat& bgr, bool& searched,
                                       bool color_only, const SearchBar& bar) {
  searched = false;
  const Pose last_good = search_reference();
  if (search_ && search_->ready() && !bgr.empty() &&
      monitor_.color_level() >= TrackQualityMonitor::kMinColorLevel) {
    // Hypotheses: the best colour placements, each at the last good rotation and turned by
    // +-color_search_rotation_deg about the camera axes (the object may have turned while it
    // was hidden), plus the last good pose and the last frame's; each refined, the best colour
    // contrast wins.
    const PinholeCamera& camera = tracker_->camera();
    const double reach_px = search_reach_px();
    if (!frame_search_.searched) {
      frame_search_.found = search_->search(bgr, last_good, camera, reach_px);
      frame_search_.searched = true;
    }
    std::vector<SearchCandidate> found = frame_search_.found;
    if (static_cast<int>(found.size()) > params_.color_search_placements)
      found.resize(static_cast<std::size_t>(params_.color_search_placements));
    // found: best contrast first.
    if (std::isfinite(bar.min_contrast)) {
      const double level = monitor_.color_level();
      if (found.empty() ||
          found.front().contrast < bar.min_contrast - kTrackedSearchRefineSlack * level) {
        // As a refined search would: the best placement confirms the next frame's (while lost)
        // when it is at least color_confirm_ratio x the level.
        unconfirmed_.reset();
        if (!found.empty() && params_.color_confirm_ratio > 0.0 &&
            found.front().contrast >= params_.color_confirm_ratio * level)
          unconfirmed_ = found.front().object_to_camera;
        return TrackResult();
      }
      // The same slack per placement: a placement far below the bar is not refined, nor are its
      // turns (found is best first, so the kept ones are a prefix).
      const auto far_below = [&](const SearchCandidate& c) {
        return c.contrast < bar.min_contrast - kTrackedSearchRefineSlack * level;
      };
      found.erase(std::find_if(found.begin(), found.end(), far_below), found.end());
    }
    std::vector<Pose> hypotheses{last_good};
    const Eigen::Vector3d& center_object = tracker_->center_object();
    // The pose the last frame ended at (a placement taken while lost, or where the pipeline
    // went): the object moves on between frames, so last frame's find is this frame's best start.
    // Not when it went behind the camera (a long extrapolation): it cannot be refined.
    const Pose& last = tracker_->last_pose();
    if (is_valid_pose(last) && last.translation().z() > 0.0 &&
        ((last * center_object) - (last_good * center_object)).norm() >
            0.05 * tracker_->diameter_m())
      hypotheses.push_back(last);
    const double angle = params_.color_search_rotation_deg * M_PI / 180.0;
    const std::size_t first_placed = hypotheses.size();
    for (const SearchCandidate& candidate : found) {
      const Pose& placed = candidate.object_to_camera;
      hypotheses.push_back(placed);
      if (angle <= 0.0) continue;
      for (const Pose& turned : turned_about_center(placed, center_object, angle))
        hypotheses.push_back(turned);
    }
    keep_best_placements(bgr, first_placed, hypotheses);
    std::vector<TrackResult> refined = refine_once(frame, hypotheses);
    if (refined.front().status != TrackStatus::kReacquired) return refined.front();  // invalid frame
    std::vector<Pose> refined_poses;
    for (const TrackResult& r : refined) refined_poses.push_back(r.object_to_camera);
    const std::vector<SearchCandidate> scored = score_once(bgr, refined_poses);
    // A hypothesis the refinement took out of reach is not a candidate (the last good pose,
    // the first, is the fallback).
    const auto candidate = [&](std::size_t i) { return i == 0 || within_reach(refined_poses[i], reach_px); };
    // The learned surface's agreement with this frame at a pose (texture_ ready).
    const auto surface_at = [&](const Pose& pose) {
      return texture_->agreement(texture_->prepare(bgr, pose, camera), pose, camera);
    };
    std::size_t best_index = 0;
    for (std::size_t i = 1; i < scored.size(); ++i)
      if (scored[i].contrast > scored[best_index].contrast && candidate(i)) best_index = i;
    if (record_hypotheses_)
      for (std::size_t i = 0; i < refined.size(); ++i) {
        HypothesisRecord record;
        record.start_object_to_camera = hypotheses[i];
        record.object_to_camera = refined_poses[i];
        record.contrast = scored[i].contrast;
        record.energy = refined[i].energy_after;
        record.in_reach = candidate(i);
        record.chosen = i == best_index;
        record.reacquiring = monitor_.should_reacquire();
        if (texture_ && texture_->ready() && texture_->has_color_pattern()) {
          const TextureAgreement a = surface_at(refined_poses[i]);
          if (a.points >= SurfaceTexture::kMinPoints) record.surface_correlation = a.correlation;
        }
        frame_hypotheses_.push_back(record);
      }
    TrackResult best = refined[best_index];
    const double best_contrast = scored[best_index].contrast;
    // color_confirm_ratio: a weaker best hypothesis counts when the previous frame's best was at
    // the same place.
    bool confirmed = false;
    if (params_.color_confirm_ratio > 0.0 &&
        best_contrast >= params_.color_confirm_ratio * monitor_.color_level()) {
      const Pose& pose = best.object_to_camera;
      confirmed = unconfirmed_ && ((*unconfirmed_ * center_object) - (pose * center_object)).norm() <
                                      0.25 * tracker_->diameter_m();
      unconfirmed_ = pose;
    } else {
      unconfirmed_.reset();
    }
    if (best_contrast < bar.min_contrast || best.energy_after < bar.min_energy) return TrackResult();
    if (std::isfinite(bar.min_surface_correlation) && texture_ && texture_->ready()) {
      const Pose& pose = best.object_to_camera;
      const TextureAgreement agreement = surface_at(pose);
      // A find that shows too little of the learned surface cannot stand against a held pose
      // whose surface agrees.
      if (agreement.points < SurfaceTexture::kMinPoints ||
          agreement.correlation < bar.min_surface_correlation)
        return TrackResult();
    }
    if (best_contrast >= params_.color_accept_ratio * monitor_.color_level() || confirmed ||
        best_contrast >= bar.accept_contrast) {
      // The taken pose confirms the next frame's best when it is at the same place: while the
      // track stays lost, a confirmed placement is not asked to wait a frame again.
      unconfirmed_ = best.object_to_camera;
      searched = true;
      tracker_->adopt(frame, best);
      return best;
    }
  }
  if (color_only) return TrackResult();
  if (params_.track_while_lost) return tracker_->track(frame);
  return tracker_->reacquire(frame, last_good, monitor_.params().reacquire_search_scale);
}

void TrackingSession::keep_best_placements(const cv::Mat& bgr, std::size_t first_placed,
                                           std::vector<Pose>& hypotheses) {
  const auto keep = static_cast<std::size_t>(params_.color_search_refined);
  if (keep == 0 || hypotheses.size() - first_placed <= keep) return;
  const std::vector<Pose> placed(hypotheses.begin() + static_cast<std::ptrdiff_t>(first_placed),
                                 hypotheses.end());
  const std::vector<SearchCandidate> scored = score_once(bgr, placed);
  std::vector<std::size_t> order(placed.size());
  std::iota(order.begin(), order.end(), 0);
  // Best contrast first; a tie keeps the search's order.
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return scored[a].contrast > scored[b].contrast;
  });
  order.resize(keep);
  std::sort(order.begin(), order.end());  // the kept ones in the search's order
  hypotheses.resize(first_placed);
  for (const std::size_t i : order) hypotheses.push_back(placed[i]);
}

Pose TrackingSession::search_reference() const {
  Pose reference = monitor_.last_good_pose();
  const double ratio = params_.trusted_depth_ratio;
  const Eigen::Vector3d center = reference * tracker_->center_object();
  if (!(ratio > 0.0) || !(trusted_depth_m_ > 0.0) || !(center.z() > 0.0)) return reference;
  const double depth = std::clamp(center.z(), trusted_depth_m_ / ratio, trusted_depth_m_ * ratio);
  reference.translation() += (depth / center.z() - 1.0) * center;  // along the viewing ray
  return reference;
}

double TrackingSession::center_depth_m(const Pose& object_to_camera) const {
  return (object_to_camera * tracker_->center_object()).z();
}

bool TrackingSession::outside_trusted_depth(const Pose& object_to_camera) const {
  const double ratio = params_.trusted_depth_ratio;
  if (!(ratio > 0.0) || !(trusted_depth_m_ > 0.0)) return false;
  const double depth = center_depth_m(object_to_camera);
  return !(depth >= trusted_depth_m_ / ratio && depth <= trusted_depth_m_ * ratio);
}

TrackResult TrackingSession::refine_from(const Frame& frame, const Pose& start) {
  if (!tracker_ || monitor_.state() == TrackState::kWaitingForPose) {
    TrackResult none;
    none.status = TrackStatus::kNotInitialized;
    return none;
  }
  return tracker_->refine_hypotheses(frame, {start}, 1.0, false).front();
}

std::vector<TrackResult> TrackingSession::refine_once(const Frame& frame,
                                                     const std::vector<Pose>& hypotheses) {
  return once_per_frame(
      hypotheses, frame_search_.starts, frame_search_.refined,
      [&](const std::vector<Pose>& fresh) { return tracker_->refine_hypotheses(frame, fresh, 1.0); },
      // An invalid frame's results are not kept: every later call reports it again.
      [](const TrackResult& r) { return r.status == TrackStatus::kReacquired; });
}

std::vector<SearchCandidate> TrackingSession::score_once(const cv::Mat& bgr,
                                                         const std::vector<Pose>& poses) {
  return once_per_frame(
      poses, frame_search_.scored, frame_search_.scores,
      // One batch: the poses are scored in parallel.
      [&](const std::vector<Pose>& fresh) { return search_->score(bgr, fresh, tracker_->camera()); },
      [](const SearchCandidate&) { return true; });
}

bool TrackingSession::repeats_previous_find(const SessionResult& result) {
  if (!(params_.repeat_recover_diameters > 0.0) || !result.reacquiring ||
      result.frame.status != TrackStatus::kReacquired) {
    previous_find_.reset();
    return false;
  }
  const Pose& pose = result.frame.object_to_camera;
  const bool repeats = previous_find_ && same_place(*previous_find_, pose,
                                                    params_.repeat_recover_diameters,
                                                    params_.repeat_recover_deg);
  previous_find_ = pose;
  return repeats;
}

bool TrackingSession::same_place(const Pose& a, const Pose& b, double diameters, double deg) const {
  const Eigen::Vector3d& center = tracker_->center_object();
  return ((a * center) - (b * center)).norm() < diameters * tracker_->diameter_m() &&
         rotation_error_deg(a, b) < deg;
}

bool TrackingSession::within_reach(const Pose& object_to_camera, double reach_px) const {
  if (reach_px <= 0.0) return true;
  const Eigen::Vector3d& center = tracker_->center_object();
  const Eigen::Vector3d c = object_to_camera * center;
  const PinholeCamera& camera = tracker_->camera();
  // search_reach_px() is 0 when the last good pose's centre is not in front of the camera.
  return c.z() > 0.0 &&
         (camera.project(c) - camera.project(monitor_.last_good_pose() * center)).norm() <= reach_px;
}

double TrackingSession::search_reach_px() const {
  if (!(params_.color_search_reach_diameters > 0.0)) return 0.0;
  const Pose& last_good = monitor_.last_good_pose();
  const double depth_m = center_depth_m(last_good);
  if (!(depth_m > 0.0)) return 0.0;
  // This frame is consecutive_bad_frames() + 1 frames after the last good one.
  return params_.color_search_reach_diameters * (monitor_.consecutive_bad_frames() + 1) *
         tracker_->diameter_m() * tracker_->camera().fx() / depth_m;
}

bool TrackingSession::relocalize(const Frame& frame, const cv::Mat& gray, SessionResult& result) {
  if (relocalizer_->keyframes() == 0) return false;
  if ((reacquiring_frames_ - 1) % params_.relocalization_interval_frames != 0) return false;
  // As the colour search's hypotheses: not farther than the object could have gone
  // (color_search_reach_diameters; a clutter thing wearing the object's texture matches too).
  // The features are detected only where it can be: the object's rectangle at the last good
  // pose grown by the reach (the whole frame once the reach covers it). Cheaper on the first
  // lost frames, and ORB's feature budget is not spent on clutter the pose may not go to.
  const double reach_px = search_reach_px();
  cv::Rect region;  // empty: the whole frame
  if (reach_px > 0.0) {
    region = relocalizer_->region_around(monitor_.last_good_pose(), tracker_->camera(), 0.0, reach_px);
    if (region.area() <= 0) return false;
  }
  const Relocalization found = relocalizer_->locate(gray, tracker_->camera(), region);
  if (!found.found) return false;
  if (!within_reach(found.object_to_camera, reach_px)) return false;
  adopt_relocalized(frame, found.object_to_camera, result);
  return true;
}

void TrackingSession::adopt_relocalized(const Frame& frame, const Pose& object_to_camera,
                                        SessionResult& result) {
  TrackResult located;
  located.status = TrackStatus::kReacquired;
  located.object_to_camera = located.preliminary_object_to_camera = object_to_camera;
  tracker_->adopt(frame, located);
  result.frame = located;
  result.relocalized = true;
}

void TrackingSession::use_features(const Frame& frame, const cv::Mat& gray, SessionResult& result,
                                   bool in_doubt) {
  const TrackStatus status = result.frame.status;
  if (relocalizer_->keyframes() == 0 ||
      (status != TrackStatus::kKeypoints && status != TrackStatus::kExtrapolated &&
       status != TrackStatus::kReacquired))
    return;
  const Pose& held = result.frame.object_to_camera;
  const PinholeCamera& camera = tracker_->camera();
  Relocalization found =
      relocalizer_->locate(gray, camera, relocalizer_->region_around(held, camera, kRegionMargin));
  // In doubt by the surface and not found near the held pose, the object may be anywhere: the
  // whole frame (second: near the held pose ORB's feature budget is spent on the object, over
  // the whole frame much of it on clutter).
  if (!found.found && in_doubt && params_.relocalization_doubt_whole_frame)
    found = relocalizer_->locate(gray, camera);
  if (!found.found) return;
  if (same_place(held, found.object_to_camera, kAgreementDiameters, kAgreementDeg)) {
    features_confirm_ = true;
    return;
  }
  // A pose from many features that disagrees with the held one replaces it when the track is in
  // doubt (KLT failed on this frame, or the last frame was bad): its anchors may lie on
  // something else. A confident track is kept: repeated texture (Castle-simu's bricks) gives
  // 25 consistent but wrong matches.
  if (found.inliers < params_.relocalization_override_inliers) return;
  if (status == TrackStatus::kKeypoints && monitor_.last_good() && !in_doubt) return;
  adopt_relocalized(frame, found.object_to_camera, result);
}

bool TrackingSession::surface_disagrees(const SessionResult& result) const {
  // Only a colour pattern's correlation says where the surface is (a plain object's "pattern"
  // is its shading). A frame a check or search corrected has its own, better-founded pose.
  const TrackStatus status = result.frame.status;
  return params_.relocalization_below_correlation > 0.0 && relocalizer_ && texture_ &&
         texture_->has_color_pattern() && !result.reacquiring && !result.rotation_corrected &&
         !result.texture_corrected && !result.searched &&
         (status == TrackStatus::kKeypoints || status == TrackStatus::kExtrapolated) &&
         std::isfinite(result.texture_correlation) &&
         result.texture_correlation < params_.relocalization_below_correlation;
}

bool TrackingSession::checkable(const TrackResult& held, const cv::Mat& bgr) const {
  return search_ && search_->ready() && !bgr.empty() && held.refined &&
         monitor_.color_level() >= TrackQualityMonitor::kMinColorLevel &&
         (held.status == TrackStatus::kKeypoints || held.status == TrackStatus::kExtrapolated);
}

void TrackingSession::search_if_faded(const Frame& frame, const cv::Mat& bgr, SessionResult& result,
                                      double ratio, bool must_beat_held) {
  const TrackResult& held = result.frame;
  if (!(ratio > 0.0) || !checkable(held, bgr)) return;
  // The held pose's colours, for use_colors; a check that ran before (check_rotation) has
  // scored them already.
  if (!result.color.valid)
    result.color = evidence_of(score_once(bgr, held.object_to_camera));
  const double held_contrast = result.color.contrast;
  const double level = monitor_.color_level();
  if (!(held_contrast < ratio * level)) return;
  SearchBar bar;
  if (must_beat_held) {
    bar.min_contrast = held_contrast + kTrackedSearchMargin * level;
    bar.min_energy = std::max(kTrackedSearchMinEnergyRatio * held.energy_after,
                              kTrackedSearchMinEnergyLevel * monitor_.energy_level());
    if (params_.tracked_search_surface_drop > 0.0 && texture_ && texture_->ready() &&
        texture_->has_color_pattern() &&
        result.texture_correlation >= kSurfaceDropMinHeldCorrelation)  // NaN: not scored
      bar.min_surface_correlation = result.texture_correlation - params_.tracked_search_surface_drop;
  } else if (params_.extrapolated_accept_margin > 0.0) {
    const double floor_ratio = params_.color_confirm_ratio > 0.0 ? params_.color_confirm_ratio : 0.5;
    bar.accept_contrast =
        std::max(held_contrast + params_.extrapolated_accept_margin * level, floor_ratio * level);
  }
  bool searched = false;
  const TrackResult found = reacquire(frame, bgr, searched, true, bar);
  if (!searched) return;
  result.frame = found;
  result.searched = true;
  result.color = ColorEvidence();  // scored again at the found pose
}

void TrackingSession::check_rotation(const Frame& frame, const cv::Mat& bgr, SessionResult& result) {
  const TrackResult& held = result.frame;
  if (!(params_.rotation_check_deg > 0.0) || !checkable(held, bgr) ||
      frames_since_doubt_ > params_.rotation_check_frames)
    return;
  const std::vector<Pose> turned = turned_about_center(
      held.object_to_camera, tracker_->center_object(), params_.rotation_check_deg * M_PI / 180.0);
  // Turned about the held pose's centre: the place is the held one's, no shift search.
  std::vector<TrackResult> refined = tracker_->refine_hypotheses(frame, turned, 1.0, false);
  std::vector<Pose> poses{held.object_to_camera};
  for (const TrackResult& r : refined) poses.push_back(r.object_to_camera);
  const std::vector<SearchCandidate> scored = score_once(bgr, poses);
  const Eigen::Vector3d& center = tracker_->center_object();
  const Eigen::Vector3d held_center = held.object_to_camera * center;
  std::size_t best = 0;
  for (std::size_t i = 1; i < scored.size(); ++i)
    if (refined[i - 1].refined && refined[i - 1].energy_after >= held.energy_after &&
        (poses[i] * center - held_center).norm() < kRotationCheckMaxShiftDiameters * tracker_->diameter_m() &&
        scored[i].contrast >= params_.color_accept_ratio * monitor_.color_level() &&
        scored[i].contrast >= scored[0].contrast + params_.rotation_check_margin * monitor_.color_level() &&
        scored[i].contrast > scored[best].contrast)
      best = i;
  // The same turn must win on two consecutive frames: a single win is often colour noise.
  const int winner = static_cast<int>(best) - 1;
  const bool confirmed = winner >= 0 && winner == rotation_check_winner_;
  rotation_check_winner_ = winner;
  // The kept pose's colours are scored already (use_colors takes them).
  if (!confirmed) {
    result.color = evidence_of(scored[0]);
    return;
  }
  result.color = evidence_of(scored[best]);
  rotation_check_winner_ = -1;
  TrackResult chosen = refined[best - 1];
  tracker_->adopt(frame, chosen);
  result.frame = chosen;
  result.rotation_corrected = true;
}

void TrackingSession::check_texture(const Frame& frame, const cv::Mat& bgr, SessionResult& result) {
  const TrackResult& held = result.frame;
  if (!texture_ || !texture_->ready() || !checkable(held, bgr)) return;
  // The turns about the object's axes run in rotation_check's window (every frame for a colour
  // pattern); the alignment, when on, on every frame.
  const bool turns_due = frames_since_doubt_ <= params_.rotation_check_frames ||
                         (params_.texture_check_every_frame && texture_->has_color_pattern());
  if (!turns_due && !(params_.texture_align_below > 0.0)) return;
  const PinholeCamera& camera = tracker_->camera();
  const Pose& held_pose = held.object_to_camera;
  const PreparedFrame prepared = texture_->prepare(bgr, held_pose, camera);
  const TextureAgreement held_agreement = texture_->agreement(prepared, held_pose, camera);
  const double held_correlation = held_agreement.correlation;
  if (held_agreement.points >= SurfaceTexture::kMinPoints) result.texture_correlation = held_correlation;
  if (held_agreement.points >= SurfaceTexture::kMinPoints &&
      (shift_by_texture(frame, bgr, prepared, held_correlation, result) ||
       align_by_texture(frame, bgr, prepared, held_correlation, result)))
    return;
  if (!turns_due) return;
  // Turns about the object's own axes through its centre, k x step for k = 1 .. n - 1.
  const Eigen::Vector3d& center = tracker_->center_object();
  const Eigen::Vector3d held_center = held_pose * center;
  const int steps = static_cast<int>(std::lround(360.0 / params_.texture_check_step_deg));
  const auto turned = [&](int axis, double angle_rad) {
    Pose p = held_pose;
    p.linear() = held_pose.linear() * Eigen::AngleAxisd(angle_rad, Eigen::Vector3d::Unit(axis)).toRotationMatrix();
    p.translation() = held_center - p.linear() * center;
    return p;
  };
  const double step_rad = 2.0 * M_PI / steps;
  int winner = -1;
  double best_correlation =
      std::max(held_correlation + params_.texture_check_margin, kTextureCheckMinCorrelation);
  Pose best_pose = held_pose;
  for (int axis = 0; axis < 3; ++axis)
    for (int k = 1; k < steps; ++k) {
      const Pose p = turned(axis, k * step_rad);
      const TextureAgreement a = texture_->agreement(prepared, p, camera);
      if (a.points >= SurfaceTexture::kMinPoints && a.correlation >= best_correlation) {
        best_correlation = a.correlation;
        winner = axis * steps + k;
        best_pose = p;
      }
    }
  // The winning turn's angle to a sixth of the step (the outline does not fix a turn about a
  // symmetry axis, so the refinement will not).
  if (winner >= 0) {
    const int axis = winner / steps, k = winner % steps;
    for (const double offset : {-2.0, -1.0, 1.0, 2.0}) {
      const Pose p = turned(axis, (k + offset / 6.0) * step_rad);
      const TextureAgreement a = texture_->agreement(prepared, p, camera);
      if (a.points >= SurfaceTexture::kMinPoints && a.correlation > best_correlation) {
        best_correlation = a.correlation;
        best_pose = p;
      }
    }
  }
  // The same turn must win on two consecutive frames before it is refined and tried.
  const bool confirmed = winner >= 0 && winner == texture_check_winner_;
  texture_check_winner_ = winner;
  if (!confirmed) return;
  texture_check_winner_ = -1;
  // Two ways the turn may replace the held pose. Refined (contour only), when it still matches
  // the surface better. Or as it is, when its outline is the held one's (its colour contrast
  // nearly the held pose's): a turn about a symmetry axis, which the refinement cannot fix and
  // often scrambles; its contour energy is then the held pose's.
  TrackResult refined = tracker_->refine_hypotheses(frame, {best_pose}, 1.0).front();
  const std::vector<SearchCandidate> colors =
      score_once(bgr, {held_pose, refined.object_to_camera, best_pose});
  const double level = monitor_.color_level();
  const auto kept_place = [&](const Pose& p) {
    return (p * center - held_center).norm() < kRotationCheckMaxShiftDiameters * tracker_->diameter_m();
  };
  const double refined_correlation =
      refined.refined ? texture_->agreement(prepared, refined.object_to_camera, camera).correlation
                      : std::numeric_limits<double>::quiet_NaN();
  const bool refined_better =
      refined.refined &&
      refined_correlation >=
          std::max(held_correlation + params_.texture_check_margin, kTextureCheckMinCorrelation) &&
      refined.energy_after >= kTextureCheckMinEnergyRatio * held.energy_after &&
      kept_place(refined.object_to_camera) &&
      colors[1].contrast >= params_.color_accept_ratio * level;
  const bool same_outline = colors[2].contrast >= colors[0].contrast - kSameOutlineContrastTolerance * level &&
                            colors[2].contrast >= params_.color_accept_ratio * level;
  if (!refined_better && !same_outline) return;
  TrackResult chosen = refined;
  if (!refined_better) {
    chosen = held;
    chosen.status = TrackStatus::kReacquired;
    chosen.object_to_camera = best_pose;
  }
  tracker_->adopt(frame, chosen);
  result.frame = chosen;
  result.color = evidence_of(colors[refined_better ? 1 : 2]);
  result.texture_corrected = true;
  result.texture_correlation = refined_better ? refined_correlation : best_correlation;
}

bool TrackingSession::align_by_texture(const Frame& frame, const cv::Mat& bgr,
                                       const PreparedFrame& prepared, double held_correlation,
                                       SessionResult& result) {
  const double below = params_.texture_align_below;
  if (!(below > 0.0) || !(held_correlation < below)) return false;
  const PinholeCamera& camera = tracker_->camera();
  const TrackResult& held = result.frame;
  const TextureAlignment aligned =
      texture_->align(prepared, held.object_to_camera, camera, kAlignMaxTurnDeg * M_PI / 180.0,
                      kAlignMaxShiftDiameters * tracker_->diameter_m(), kAlignMaxEvaluations);
  const double needed =
      std::max(held_correlation + params_.texture_check_margin, kTextureCheckMinCorrelation);
  if (!(aligned.agreement.correlation >= needed)) return false;
  // Refined without the shift search (the place is the aligned one's): the outline alone may
  // pull it back to the held pose, so the surface is asked again.
  return take_if_surface_agrees(frame, bgr, prepared, aligned.object_to_camera, needed, false,
                                result);
}

bool TrackingSession::shift_by_texture(const Frame& frame, const cv::Mat& bgr,
                                       const PreparedFrame& prepared, double held_correlation,
                                       SessionResult& result) {
  const double below = params_.texture_shift_search_below;
  if (!(below > 0.0) || !texture_->has_color_pattern() || !(held_correlation < below)) return false;
  const PinholeCamera& camera = tracker_->camera();
  const TrackResult& held = result.frame;
  const double diameter_m = tracker_->diameter_m();
  const double needed = std::max(held_correlation + params_.texture_check_margin, below);
  const TextureShift best = texture_->best_shift(prepared, held.object_to_camera, camera,
                                                 kShiftStepDiameters * diameter_m, kShiftSteps,
                                                 kShiftDepthStep);
  const bool found = best.agreement.correlation >= needed;
  // The same shift (relative to the held pose) must be found on two consecutive searches.
  const bool confirmed = found && texture_shift_winner_m_ &&
                         (*texture_shift_winner_m_ - best.shift_camera_m).norm() <
                             kShiftConfirmDiameters * diameter_m;
  texture_shift_winner_m_.reset();
  if (found && !confirmed) texture_shift_winner_m_ = best.shift_camera_m;
  if (!confirmed) return false;
  return take_if_surface_agrees(frame, bgr, prepared, best.object_to_camera, needed, true, result);
}

bool TrackingSession::take_if_surface_agrees(const Frame& frame, const cv::Mat& bgr,
                                             const PreparedFrame& prepared, const Pose& found,
                                             double needed, bool shift_search,
                                             SessionResult& result) {
  const TrackResult& held = result.frame;
  const PinholeCamera& camera = tracker_->camera();
  TrackResult refined = tracker_->refine_hypotheses(frame, {found}, 1.0, shift_search).front();
  const SearchCandidate colors = score_once(bgr, refined.object_to_camera);
  const TextureAgreement agreement =
      texture_->agreement(prepared, refined.object_to_camera, camera);
  if (!refined.refined || agreement.points < SurfaceTexture::kMinPoints ||
      agreement.correlation < needed ||
      refined.energy_after < kTextureCheckMinEnergyRatio * held.energy_after ||
      colors.contrast < params_.color_accept_ratio * monitor_.color_level())
    return false;
  tracker_->adopt(frame, refined);
  result.frame = refined;
  result.color = evidence_of(colors);
  result.texture_corrected = true;
  result.texture_correlation = agreement.correlation;
  return true;
}

void TrackingSession::add_keyframe_if_due(const cv::Mat& gray, const SessionResult& result) {
  if (!result.has_pose()) return;
  const TrackResult& f = result.frame;
  const bool given = f.status == TrackStatus::kInitialized;
  const bool confident = f.status == TrackStatus::kKeypoints && monitor_.last_good() &&
                         result.state == TrackState::kTracking && features_confirm_ &&
                         monitor_.last_quality() >= kKeyframeMinQuality &&
                         f.keypoints.inlier_ratio >= kKeyframeMinInlierRatio;
  if ((given || confident) && relocalizer_->wants_keyframe(f.object_to_camera))
    relocalizer_->add_keyframe(gray, f.object_to_camera, tracker_->camera());
}

void TrackingSession::use_colors(const cv::Mat& bgr, SessionResult& result) {
  if (!search_ || bgr.empty() || !result.has_pose()) return;
  const Pose& pose = result.frame.object_to_camera;
  if (result.frame.status == TrackStatus::kInitialized) {
    search_->learn(bgr, pose, tracker_->camera());
    frames_since_learning_ = 0;
    return;
  }
  if (!search_->ready() || result.color.valid) return;  // valid: scored by check_rotation
  result.color = evidence_of(score_once(bgr, pose));
}

SessionResult TrackingSession::track(const Frame& frame) {
  const auto start = std::chrono::steady_clock::now();
  SessionResult result;
  result.previous_state = monitor_.state();
  result.time_jumped_back = time_jumps_back(frame.stamp_s);
  has_last_stamp_ = true;
  last_stamp_s_ = frame.stamp_s;
  if (!tracker_) {
    result.state = monitor_.state();
    result.frame.message = "no camera yet";
    ++statistics_.frames;
    return result;
  }
  if (result.time_jumped_back && restart_pose_ && !initialized_since_last_frame_ &&
      monitor_.state() != TrackState::kWaitingForPose) {
    initialize(*restart_pose_);
    result.restarted = true;
    result.previous_state = monitor_.state();
    ++statistics_.restarts;
  }
  initialized_since_last_frame_ = false;

  result.reacquiring = monitor_.should_reacquire();
  reacquiring_frames_ = result.reacquiring ? reacquiring_frames_ + 1 : 0;
  if (!result.reacquiring) unconfirmed_.reset();
  frame_search_ = FrameSearch();
  frame_hypotheses_.clear();
  // The colour frame, when the colour model is on and the frame is in colour (checked first:
  // an invalid frame is the tracker's to report).
  cv::Mat bgr;
  if (search_ && frame.image.type() == CV_8UC3 && frame.image.size() == tracker_->camera().size() &&
      !ObjectSearch::looks_grey(frame.image))
    bgr = tracker_->undistorted_color(frame.image);
  // The feature relocalizer's frame (undistorted grey), when it is on, the frame is usable and
  // features are matched on it (while lost, or on every frame with
  // relocalization_while_tracking; the given pose's keyframe takes it below).
  const auto features_frame = [&]() {
    return relocalizer_ && tracker_->check_frame(frame).empty() ? tracker_->undistorted_gray(frame.image)
                                                                : cv::Mat();
  };
  cv::Mat gray;
  if (result.reacquiring || params_.relocalization_while_tracking) gray = features_frame();
  features_confirm_ = false;
  if (!(result.reacquiring && !gray.empty() && relocalize(frame, gray, result))) {
    result.frame =
        result.reacquiring ? reacquire(frame, bgr, result.searched) : tracker_->track(frame);
    if (!gray.empty() && params_.relocalization_while_tracking) use_features(frame, gray, result);
    if (result.frame.status == TrackStatus::kExtrapolated)
      search_if_faded(frame, bgr, result, params_.extrapolated_search_ratio, false);
    // Only on tracked frames (kKeypoints, kExtrapolated); while lost, with check_while_lost.
    if (!result.reacquiring || params_.check_while_lost) {
      check_rotation(frame, bgr, result);
      if (!result.rotation_corrected) check_texture(frame, bgr, result);
    }
    // After the checks: a turn or a shift they found is the held pose's own correction, while
    // the colour search may take another place.
    if (result.frame.status == TrackStatus::kKeypoints && !result.rotation_corrected &&
        !result.texture_corrected)
      search_if_faded(frame, bgr, result, params_.tracked_search_ratio, true);
    if (surface_disagrees(result)) {
      if (gray.empty()) gray = features_frame();
      if (!gray.empty()) use_features(frame, gray, result, true);
    }
  }
  use_colors(bgr, result);
  if (texture_ && !bgr.empty() && result.frame.status == TrackStatus::kInitialized) {
    texture_->learn(bgr, result.frame.object_to_camera, tracker_->camera());
    set_plain_surface(texture_->size() >= SurfaceTexture::kMinPoints && !texture_->has_color_pattern());
  }
  ColorLossRule rule;
  rule.lost_ratio = params_.color_lost_ratio;
  rule.contour_veto_ratio = params_.color_contour_veto_ratio;
  rule.keypoint_veto_inliers = params_.color_keypoint_veto_inliers;
  rule.keypoint_veto_inlier_ratio = params_.color_keypoint_veto_inlier_ratio;
  rule.vanished_ratio = params_.color_vanished_ratio;
  rule.recover_ratio = params_.color_recover_ratio;
  rule.recover_min_visible = params_.color_recover_min_visible;
  rule.surface_hold_correlation = params_.surface_hold_correlation;
  rule.recover_min_surface_correlation = params_.surface_recover_correlation;
  rule.extrapolated_good_frames = params_.extrapolated_good_frames;
  rule.outside_trusted_depth = result.has_pose() && result.frame.status != TrackStatus::kInitialized &&
                               outside_trusted_depth(result.frame.object_to_camera);
  // Only a colour pattern's correlation says where the surface is (a grey object's "pattern" is
  // its shading, which a wrong pose of the castle matched at >= 0.7: hard2/castle/leave -5.5).
  if (texture_ && texture_->has_color_pattern())
    result.color.surface_correlation = result.texture_correlation;
  result.state = monitor_.update(result.frame, result.color, rule, repeats_previous_find(result));
  if (params_.drop_unconfirmed_anchors && result.frame.status == TrackStatus::kExtrapolated &&
      !monitor_.last_good())
    tracker_->forget_keypoints();
  if (gray.empty() && result.frame.status == TrackStatus::kInitialized) gray = features_frame();
  if (!gray.empty()) add_keyframe_if_due(gray, result);
  // rotation_check's window: frames since KLT last failed or the track was re-acquired.
  const bool doubt = result.frame.status == TrackStatus::kExtrapolated ||
                     result.frame.status == TrackStatus::kReacquired;
  frames_since_doubt_ = doubt ? 0 : frames_since_doubt_ + 1;
  if (result.has_pose()) {
    result.quality = monitor_.last_quality();
    result.good = monitor_.last_good();
    if (result.state == TrackState::kTracking && result.previous_state == TrackState::kLost)
      frames_since_recovery_ = 0;
    if (result.state == TrackState::kTracking && result.good &&
        ++frames_since_recovery_ >= kTrustAfterFrames) {
      const double depth = center_depth_m(result.frame.object_to_camera);
      if (depth > 0.0) trusted_depth_m_ = depth;
    }
    // Colours are learned on good frames while tracking, every color_learn_interval_frames.
    if (search_ && !bgr.empty() && result.good && result.state == TrackState::kTracking &&
        result.frame.status != TrackStatus::kInitialized &&
        ++frames_since_learning_ >= params_.color_learn_interval_frames) {
      search_->learn(bgr, result.frame.object_to_camera, tracker_->camera());
      frames_since_learning_ = 0;
    }
  }
  result.hypotheses = std::move(frame_hypotheses_);  // cleared again when the next frame starts
  // The whole call: tracking, checks, colour search and learning.
  result.frame.frame_time_ms = elapsed_ms(start);
  count(result);
  return result;
}

void TrackingSession::count(const SessionResult& result) {
  SessionStatistics& s = statistics_;
  ++s.frames;
  if (result.frame.status == TrackStatus::kInvalidInput) ++s.invalid_frames;
  if (result.state == TrackState::kLost) ++s.frames_lost;
  if (result.previous_state == TrackState::kTracking && result.state == TrackState::kLost) {
    ++s.losses;
    lost_at_frame_ = s.frames;
  }
  if (result.previous_state == TrackState::kLost && result.state == TrackState::kTracking) {
    ++s.reacquisitions;
    if (lost_at_frame_ >= 0) s.frames_to_reacquire.push_back(s.frames - lost_at_frame_);
    lost_at_frame_ = -1;
  }
}

}  // namespace kct
