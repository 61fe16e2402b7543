#include "klt_contour_tracker/core/tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "klt_contour_tracker/core/elapsed.h"
#include "klt_contour_tracker/core/mesh_simplification.h"
#include "klt_contour_tracker/core/motion_model.h"
#include "klt_contour_tracker/core/motion_prior_cost.h"
#include "klt_contour_tracker/core/plausibility.h"
#include "klt_contour_tracker/core/pose_refiner.h"
#include "klt_contour_tracker/core/region_cost.h"
#include "klt_contour_tracker/core/worker_threads.h"

namespace kct {

const char* to_string(TrackStatus status) {
  switch (status) {
    case TrackStatus::kNotInitialized: return "not_initialized";
    case TrackStatus::kInitialized: return "initialized";
    case TrackStatus::kKeypoints: return "keypoints";
    case TrackStatus::kExtrapolated: return "extrapolated";
    case TrackStatus::kInvalidInput: return "invalid_input";
    case TrackStatus::kReacquired: return "reacquired";
  }
  return "unknown";
}

Tracker::Tracker(std::shared_ptr<const Mesh> mesh, const PinholeCamera& camera,
                 const TrackerParams& params)
    : mesh_(std::move(mesh)), params_(params), keypoints_(mesh_, params) {
  if (!mesh_ || mesh_->faces.empty()) throw std::invalid_argument("Tracker: empty mesh");
  params_.validate();
  diameter_m_ = mesh_->diameter();
  center_object_ = mesh_->bounding_box_center();
  const std::string size_error = implausible_diameter(diameter_m_);
  if (!size_error.empty()) throw std::invalid_argument("Tracker: " + size_error);
  keypoints_.set_object_extent(diameter_m_, center_object_);
  set_camera(camera);
  if (params_.refine) refiner_ = std::make_unique<PoseRefiner>(mesh_, params_);
  configure_coarse_refiner();
  workers_ = std::make_unique<WorkerThreads>(params_.num_threads);
  configure_motion_model();
  configure_cues();
}

Tracker::~Tracker() = default;

void Tracker::configure_coarse_refiner() {
  coarse_refiner_odd_.reset();  // a replica, made again when next needed
  if (!(params_.refine && params_.hypothesis_mesh_error_diameters > 0.0)) {
    coarse_refiner_.reset();
    return;
  }
  if (!coarse_mesh_ || coarse_mesh_error_diameters_ != params_.hypothesis_mesh_error_diameters) {
    coarse_mesh_ = std::make_shared<const Mesh>(
        simplified_mesh(*mesh_, params_.hypothesis_mesh_error_diameters * diameter_m_));
    coarse_mesh_error_diameters_ = params_.hypothesis_mesh_error_diameters;
    coarse_refiner_.reset();
  }
  // Built now, not on the first lost frame: its visibility table takes up to a second.
  if (!coarse_refiner_)
    coarse_refiner_ = std::make_unique<PoseRefiner>(coarse_mesh_, params_);
  else
    coarse_refiner_->set_params(params_);  // rebuilds only what the new parameters change
}

void Tracker::configure_cues() {
  region_cost_.reset();
  motion_prior_.reset();
  if (!refiner_) return;
  refiner_->clear_cues();
  if (!params_.refine || params_.optimizer != "coarse_to_fine") return;
  if (params_.region_weight > 0.0) {
    RegionCueSettings settings;
    settings.line_half_length_px = params_.region_line_half_length_px;
    settings.line_spacing_px = params_.region_line_spacing_px;
    region_cost_ =
        std::make_shared<RegionCost>(refiner_->shared_contour_extractor(), settings,
                                     params_.region_band_px, params_.region_learning_rate);
    refiner_->add_cue(region_cost_, params_.region_weight);
  }
  if (params_.motion_prior_weight > 0.0 && motion_) {
    motion_prior_ = std::make_shared<MotionPriorCost>();
    refiner_->add_cue(motion_prior_, params_.motion_prior_weight);
  }
}

cv::Mat Tracker::to_bgr(const cv::Mat& image) const {
  if (image.channels() != 3) return cv::Mat();
  if (undistort_map_x_.empty()) return image;
  cv::Mat undistorted;
  cv::remap(image, undistorted, undistort_map_x_, undistort_map_y_, cv::INTER_LINEAR);
  return undistorted;
}

void Tracker::configure_motion_model() {
  if (!params_.motion_model) {
    motion_.reset();
    return;
  }
  MotionModelSettings settings;
  settings.velocity_smoothing = params_.motion_velocity_smoothing;
  settings.error_smoothing = params_.motion_error_smoothing;
  const bool had_pose = motion_ && motion_->initialized();
  const Pose last = had_pose ? motion_->last_pose() : Pose::Identity();
  motion_ = std::make_unique<MotionModel>(center_object_, diameter_m_, settings);
  if (had_pose) motion_->reset(last);
}

Pose Tracker::predicted_pose() const {
  return motion_ && motion_->initialized() ? motion_->predict() : pose_i1_;
}

void Tracker::set_camera(const PinholeCamera& camera) {
  if (camera.width() <= 0 || camera.height() <= 0)
    throw std::invalid_argument("Tracker: camera has no image size");
  const std::string error = implausible_camera(camera);
  if (!error.empty()) throw std::invalid_argument("Tracker: implausible camera: " + error);
  camera_ = camera;
  // Frames are undistorted once with the same K, then everything uses the ideal pinhole.
  camera.undistortion_maps(undistort_map_x_, undistort_map_y_);
}

void Tracker::set_params(const TrackerParams& params) {
  params.validate();
  const bool motion_changed =
      params.motion_model != params_.motion_model ||
      params.motion_velocity_smoothing != params_.motion_velocity_smoothing ||
      params.motion_error_smoothing != params_.motion_error_smoothing;
  params_ = params;
  keypoints_.set_params(params_);
  if (params_.refine && !refiner_) refiner_ = std::make_unique<PoseRefiner>(mesh_, params_);
  if (refiner_) refiner_->set_params(params_);
  hypothesis_refiner_.reset();  // made again from the refiner when next needed
  configure_coarse_refiner();
  if (workers_->threads() != params_.num_threads)
    workers_ = std::make_unique<WorkerThreads>(params_.num_threads);
  if (motion_changed) configure_motion_model();
  configure_cues();  // the colours are learned again
}

void Tracker::initialize(const Pose& object_to_camera) {
  if (!is_valid_pose(object_to_camera))
    throw std::invalid_argument("Tracker::initialize: pose is not finite or not a rotation");
  if (object_to_camera.translation().z() <= 0)
    throw std::invalid_argument("Tracker::initialize: the object is behind the camera (z <= 0)");
  const std::string error = implausible_pose(object_to_camera, diameter_m_, center_object_, camera_);
  if (!error.empty()) throw std::invalid_argument("Tracker::initialize: implausible pose: " + error);
  pose_i1_ = pose_i2_ = object_to_camera;
  keypoints_.clear();
  if (motion_) motion_->reset(object_to_camera);
  if (region_cost_) region_cost_->forget();  // a new track may be another scene
  state_ = State::kPendingFirstFrame;
  frames_since_init_ = 0;
  frames_since_detection_ = 0;
  occluded_anchors_.clear();
}

cv::Mat Tracker::update_occlusion_mask(const KeypointResult& keypoints, const Pose& object_to_camera) {
  const double radius_px = params_.occlusion_mask_radius_px;
  if (!(radius_px > 0.0)) {
    occluded_anchors_.clear();
    return cv::Mat();
  }
  // Frames are numbered by frames_since_init_ (this frame's is counted after the refinement).
  const std::size_t lost = keypoints.lost_points_object.size();
  // Most tracks failed: blur or a jump, not something in front of part of the object.
  if (lost > 0 && lost <= static_cast<std::size_t>(keypoints.tracked))
    occluded_anchors_.emplace_back(frames_since_init_, keypoints.lost_points_object);
  const int oldest = frames_since_init_ - params_.occlusion_mask_frames + 1;
  occluded_anchors_.erase(
      std::remove_if(occluded_anchors_.begin(), occluded_anchors_.end(),
                     [&](const auto& entry) { return entry.first < oldest; }),
      occluded_anchors_.end());
  if (occluded_anchors_.empty()) return cv::Mat();
  cv::Mat mask(camera_.height(), camera_.width(), CV_8UC1, cv::Scalar(0));
  const int radius = std::max(1, static_cast<int>(std::lround(radius_px)));
  for (const auto& entry : occluded_anchors_)
    for (const Eigen::Vector3d& p : entry.second) {
      const Eigen::Vector3d q = object_to_camera * p;
      if (!(q.z() > 1e-6)) continue;
      const Eigen::Vector2d uv = camera_.project(q);
      if (!(std::abs(uv.x()) < 1e6 && std::abs(uv.y()) < 1e6)) continue;
      cv::circle(mask, cv::Point(static_cast<int>(std::lround(uv.x())), static_cast<int>(std::lround(uv.y()))),
                 radius, cv::Scalar(255), cv::FILLED);
    }
  return mask;
}

void Tracker::reset() {
  keypoints_.clear();
  state_ = State::kWaiting;
}

cv::Mat Tracker::to_gray(const cv::Mat& image) const {
  cv::Mat gray;
  if (image.channels() == 3)
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  else
    gray = image;
  if (!undistort_map_x_.empty()) {
    cv::Mat undistorted;
    cv::remap(gray, undistorted, undistort_map_x_, undistort_map_y_, cv::INTER_LINEAR);
    return undistorted;
  }
  return gray;
}

const ContourExtractor* Tracker::contour_extractor() const {
  return refiner_ ? &refiner_->contour_extractor() : nullptr;
}

void Tracker::apply_refinement(const RefineResult& refined, TrackResult& result) {
  // A refined pose that is not a rigid transform in front of the camera is not used.
  if (is_valid_pose(refined.object_to_camera) && refined.object_to_camera.translation().z() > 0) {
    result.object_to_camera = refined.object_to_camera;
    result.refined = true;
  }
  result.energy_before = refined.energy_before;
  result.energy_after = refined.energy_after;
  result.hops = refined.hops;
  result.times.image_ms = refined.times.image_ms;
  result.times.contour_extraction_ms = refined.times.contour_extraction_ms;
  result.times.energy_ms = refined.times.energy_ms;
  result.times.optimizer_ms = refined.times.optimizer_ms;
}

double Tracker::detect_keypoints(const cv::Mat& gray, TrackResult& result,
                                 bool same_frame_as_track) {
  const auto start = std::chrono::steady_clock::now();
  keypoints_.detect(gray, pose_i1_, camera_, same_frame_as_track);
  frames_since_detection_ = 0;
  const double ms = elapsed_ms(start);
  result.times.keypoint_detection_ms += ms;
  return ms;
}

std::string Tracker::check_frame(const Frame& frame) const {
  if (frame.image.empty()) return "empty image";
  if (frame.image.depth() != CV_8U || (frame.image.channels() != 1 && frame.image.channels() != 3))
    return "image type " + cv::typeToString(frame.image.type()) +
           " is not supported: 8-bit grey (CV_8UC1) or BGR (CV_8UC3)";
  // Bounded work per frame: the size is checked before anything is computed on the pixels.
  const std::string size_error =
      implausible_image_size(static_cast<std::uint64_t>(frame.image.cols),
                             static_cast<std::uint64_t>(frame.image.rows),
                             static_cast<std::uint64_t>(params_.max_image_pixels));
  if (!size_error.empty()) return size_error;
  if (frame.image.size() != camera_.size())
    return "image is " + std::to_string(frame.image.cols) + "x" + std::to_string(frame.image.rows) +
           " but the camera is " + std::to_string(camera_.width()) + "x" +
           std::to_string(camera_.height());
  return "";
}

TrackResult Tracker::refine_hypothesis(const Frame& frame, const Pose& around,
                                       double search_scale) {
  return refine_hypotheses(frame, {around}, search_scale).front();
}

std::vector<TrackResult> Tracker::refine_hypotheses(const Frame& frame,
                                                    const std::vector<Pose>& around,
                                                    double search_scale, bool shift_search) {
  const auto start = std::chrono::steady_clock::now();
  if (!(search_scale >= 1.0) || !std::isfinite(search_scale))
    throw std::invalid_argument("Tracker::reacquire: search_scale must be >= 1");
  for (const Pose& pose : around)
    if (!is_valid_pose(pose) || pose.translation().z() <= 0)
      throw std::invalid_argument("Tracker::reacquire: pose is invalid or behind the camera");
  const std::string message = check_frame(frame);
  if (!message.empty()) {
    TrackResult invalid;
    invalid.status = TrackStatus::kInvalidInput;
    invalid.message = message;
    invalid.frame_time_ms = elapsed_ms(start);
    return std::vector<TrackResult>(around.size(), invalid);
  }
  // The frame is converted once for every hypothesis; the search box is widened once.
  const bool refine = params_.refine && refiner_;
  const cv::Mat gray = refine ? to_gray(frame.image) : cv::Mat();
  // The colour frame, when the contour energy uses its chromaticity (empty for grey frames).
  const cv::Mat bgr =
      refine && params_.contour_chroma_weight > 0.0 ? to_bgr(frame.image) : cv::Mat();
  TrackerParams widened = params_;
  widened.extrapolated_rotation_bound_deg =
      std::min(180.0, params_.extrapolated_rotation_bound_deg * search_scale);
  widened.extrapolated_axial_bound *= search_scale;
  widened.extrapolated_lateral_bound *= search_scale;
  if (!shift_search) widened.shift_search_diameters = 0.0;
  if (refine) refiner_->set_params(widened);  // only the box changes: nothing is rebuilt
  // hypothesis_mesh_error_diameters: the hypotheses' contours come from the simplified mesh
  // (not with added cues: they are the tracking refiner's).
  const bool coarse = refine && params_.hypothesis_mesh_error_diameters > 0.0 &&
                      params_.optimizer == "coarse_to_fine" && !refiner_->has_added_cues();
  PoseRefiner* even_refiner = refine ? refiner_.get() : nullptr;
  if (coarse) {  // coarse_refiner_ exists: configure_coarse_refiner() made it with params_
    coarse_refiner_->set_params(widened);
    even_refiner = coarse_refiner_.get();
  }
  // With two threads and more than one hypothesis, the odd ones are refined on the worker by a
  // replica of the refiner: each refinement depends only on its hypothesis and the frame, so
  // the results do not depend on the thread count.
  const bool parallel = refine && around.size() >= 2 && workers_->threads() >= 2 &&
                        params_.optimizer == "coarse_to_fine" && !refiner_->has_added_cues();
  std::vector<TrackResult> results(around.size());
  // `refiner` null: not refined (klt_only).
  const auto refine_every_other = [&](PoseRefiner* refiner, std::size_t first, std::size_t step) {
    for (std::size_t i = first; i < around.size(); i += step) {
      TrackResult& result = results[i];
      result.status = TrackStatus::kReacquired;
      result.object_to_camera = result.preliminary_object_to_camera = around[i];
      if (!refiner) continue;
      if (!bgr.empty()) refiner->prepare_frame(gray, camera_, around[i], bgr);
      apply_refinement(refiner->refine(gray, camera_, around[i], nullptr), result);
    }
  };
  try {
    if (parallel) {
      std::unique_ptr<PoseRefiner>& odd_refiner = coarse ? coarse_refiner_odd_ : hypothesis_refiner_;
      if (!odd_refiner) odd_refiner = even_refiner->replica();
      odd_refiner->set_params(widened);
      WorkerThreads::Pending odd =
          workers_->start([&]() { refine_every_other(odd_refiner.get(), 1, 2); });
      refine_every_other(even_refiner, 0, 2);
      odd.wait();
    } else {
      refine_every_other(even_refiner, 0, 1);
    }
  } catch (...) {
    if (refine) refiner_->set_params(params_);
    throw;
  }
  if (refine) refiner_->set_params(params_);
  // The call's wall time on the first result (the others ran alongside or after it).
  if (!results.empty()) results.front().frame_time_ms = elapsed_ms(start);
  return results;
}

void Tracker::adopt(const Frame& frame, TrackResult& result) {
  if (result.status != TrackStatus::kReacquired) return;
  const auto start = std::chrono::steady_clock::now();
  pose_i1_ = pose_i2_ = result.object_to_camera;
  if (motion_) motion_->reset(pose_i1_);
  keypoints_.clear();
  detect_keypoints(to_gray(frame.image), result);
  state_ = State::kTracking;
  result.frame_time_ms += elapsed_ms(start);
}

TrackResult Tracker::reacquire(const Frame& frame, const Pose& around, double search_scale) {
  TrackResult result = refine_hypothesis(frame, around, search_scale);
  adopt(frame, result);
  return result;
}

TrackResult Tracker::track(const Frame& frame) {
  const auto start = std::chrono::steady_clock::now();
  TrackResult result;
  auto finish = [&]() {
    result.frame_time_ms = elapsed_ms(start);
    return result;
  };
  result.message = check_frame(frame);
  if (!result.message.empty()) {
    result.status = TrackStatus::kInvalidInput;
    return finish();
  }
  if (state_ == State::kWaiting) {
    result.status = TrackStatus::kNotInitialized;
    return finish();
  }
  const cv::Mat gray = to_gray(frame.image);
  // The region cue's colour frame (ours): learned from at trusted poses, scored in refine().
  // The contour energy's chromaticity (ours) reads it as well.
  const cv::Mat bgr =
      region_cost_ || params_.contour_chroma_weight > 0.0 ? to_bgr(frame.image) : cv::Mat();

  if (state_ == State::kPendingFirstFrame) {
    detect_keypoints(gray, result);
    if (region_cost_ && !bgr.empty()) region_cost_->learn(bgr, pose_i1_, camera_);
    state_ = State::kTracking;
    result.status = TrackStatus::kInitialized;
    result.object_to_camera = result.preliminary_object_to_camera = pose_i1_;
    return finish();
  }

  // Sec. 3.1 with the motion model (ours): its prediction seeds KLT and PnP, gates the tracks
  // and replaces the two-pose extrapolation when KLT fails.
  const Pose predicted = predicted_pose();
  KeypointPrediction prediction;
  if (motion_) {
    prediction.object_to_camera = predicted;
    prediction.initial_flow = params_.klt_predicted_flow;
    if (params_.keypoint_motion_gate_sigmas > 0.0) {
      // The prediction's uncertainty at the object, in px: translation and rotation about the
      // centre moving a point at the object's radius.
      const Vector6d sigma = motion_->sigma();
      const double depth_m = std::max(1e-3, (predicted * center_object_).z());
      const double radius_m = 0.5 * diameter_m_;
      const double sigma_px = camera_.fx() / depth_m *
                              (sigma.segment<2>(3).norm() + sigma.head<3>().norm() * radius_m);
      prediction.gate_px = std::max(3.0, params_.keypoint_motion_gate_sigmas * sigma_px);
    }
  }

  // The refinement's image work (pyramid, image derivatives) needs only the frame and the
  // expected pose: with a second thread it runs while KLT does. The same call is made either
  // way, so the result does not depend on num_threads.
  const bool prepare = params_.refine && refiner_ && params_.optimizer == "coarse_to_fine";
  WorkerThreads::Pending prepared;
  if (prepare && workers_->threads() >= 2)
    prepared = workers_->start([&]() { refiner_->prepare_frame(gray, camera_, predicted, bgr); });
  else if (prepare)
    refiner_->prepare_frame(gray, camera_, predicted, bgr);

  // Sec. 3.1: preliminary pose from KLT + PnP, or extrapolated when KLT fails.
  result.keypoints = keypoints_.track(gray, motion_ ? predicted : pose_i1_, camera_,
                                      motion_ ? &prediction : nullptr);
  prepared.wait();  // rethrows the preparation's exception, if any
  result.times.klt_ms = result.keypoints.klt_ms;
  result.times.pnp_ms = result.keypoints.pnp_ms;
  if (result.keypoints.success) {
    result.status = TrackStatus::kKeypoints;
    result.preliminary_object_to_camera = result.keypoints.object_to_camera;
  } else {
    result.status = TrackStatus::kExtrapolated;
    result.preliminary_object_to_camera =
        motion_ ? predicted : extrapolate_pose(pose_i2_, pose_i1_);
  }
  result.object_to_camera = result.preliminary_object_to_camera;

  // Sec. 3.2-3.4: contour energy refinement.
  if (params_.refine && refiner_) {
    if (motion_prior_ && motion_) motion_prior_->set_prediction(predicted, motion_->sigma());
    const cv::Mat occlusion_mask =
        update_occlusion_mask(result.keypoints, result.preliminary_object_to_camera);
    const RefineResult refined =
        refiner_->refine(gray, camera_, result.preliminary_object_to_camera,
                         result.keypoints.success ? &result.keypoints : nullptr, occlusion_mask);
    apply_refinement(refined, result);
  }

  // The frame's final pose seeds the extrapolation and the keypoint re-detection, so that
  // keypoint drift is corrected by the refinement (paper Fig. 4).
  pose_i2_ = pose_i1_;
  pose_i1_ = result.object_to_camera;
  if (motion_) motion_->update(pose_i1_);
  ++frames_since_init_;
  ++frames_since_detection_;
  const bool interval_due = params_.redetect_interval_frames > 0 &&
                            frames_since_detection_ >= params_.redetect_interval_frames;
  const bool agrees =
      !result.refined ||
      refined_pose_agrees_with_keypoints(result.keypoints, result.object_to_camera, camera_,
                                         params_.redetect_max_reprojection_increase_px);
  if (!result.keypoints.success || ((keypoints_.needs_redetection() || interval_due) && agrees))
    detect_keypoints(gray, result, /*same_frame_as_track=*/true);
  // The colours are learned only where keypoints and refinement agree on the pose.
  if (region_cost_ && !bgr.empty() && result.keypoints.success && agrees)
    region_cost_->learn(bgr, pose_i1_, camera_);
  return finish();
}

}  // namespace kct
