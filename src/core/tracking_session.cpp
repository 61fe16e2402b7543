#include "klt_contour_tracker/core/tracking_session.h"

#include <stdexcept>

namespace kct {

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
    tracker_ = std::make_unique<Tracker>(mesh_, camera, params_);
  else
    tracker_->set_camera(camera);
}

const Tracker& TrackingSession::tracker() const {
  if (!tracker_) throw std::logic_error("TrackingSession: no camera yet (set_camera)");
  return *tracker_;
}

void TrackingSession::initialize(const Pose& object_to_camera) {
  if (!tracker_) throw std::logic_error("TrackingSession::initialize: no camera yet (set_camera)");
  tracker_->initialize(object_to_camera);  // validates the pose
  monitor_.on_initialized(object_to_camera);
  initialized_since_last_frame_ = true;
  lost_at_frame_ = -1;
}

void TrackingSession::reset() {
  if (tracker_) tracker_->reset();
  monitor_.reset();
  initialized_since_last_frame_ = false;
  lost_at_frame_ = -1;
}

void TrackingSession::set_params(const TrackerParams& params) {
  params.validate();
  if (tracker_) tracker_->set_params(params);
  params_ = params;
}

void TrackingSession::set_quality_params(const TrackQualityParams& quality) {
  monitor_.set_params(quality);
}

TrackResult TrackingSession::reacquire(const Frame& frame) {
  return tracker_->reacquire(frame, monitor_.last_good_pose(), monitor_.params().reacquire_search_scale);
}

SessionResult TrackingSession::track(const Frame& frame) {
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
  result.frame = result.reacquiring ? reacquire(frame) : tracker_->track(frame);
  result.state = monitor_.update(result.frame);
  if (result.has_pose()) {
    result.quality = monitor_.last_quality();
    result.good = monitor_.last_good();
  }
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
