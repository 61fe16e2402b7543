#include "klt_contour_tracker/core/keypoint_tracker.h"

#include "klt_contour_tracker/core/elapsed.h"
#include "klt_contour_tracker/core/motion_model.h"
#include "klt_contour_tracker/core/pose_cost.h"
#include "klt_contour_tracker/core/pose_cv.h"
#include "klt_contour_tracker/core/search_area.h"
#include "klt_contour_tracker/core/surface_anchor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace kct {

bool refined_pose_agrees_with_keypoints(const KeypointResult& keypoints, const Pose& refined,
                                        const PinholeCamera& camera, double max_increase_px) {
  const KeypointInliers& inliers = keypoints.inlier_points;
  if (!keypoints.success || inliers.points_object.empty()) return true;
  // The search area's constraint (Sec. 3.4) with a tighter bound: <= 0 when the mean
  // reprojection error grew by at most max_increase_px.
  const ReprojectionConstraint agreement(inliers.points_object, inliers.points_image, camera,
                                         keypoints.object_to_camera, max_increase_px);
  return agreement(refined) <= 0.0;
}

Pose pose_with_motion_prior(const std::vector<Eigen::Vector3d>& points_object,
                            const std::vector<Eigen::Vector2d>& points_image,
                            const PinholeCamera& camera, const Pose& pose, const Pose& expected,
                            const Eigen::Vector3d& center_object, double sigma_rad, double sigma_m) {
  const auto residual_sum = [&](const Pose& p) {
    double sum = 0.0;
    for (std::size_t i = 0; i < points_object.size(); ++i)
      sum += (camera.project(p * points_object[i]) - points_image[i]).squaredNorm();
    return sum;
  };
  const double dof = std::max(1.0, 2.0 * points_object.size() - 6.0);
  const double inv_var_px = 1.0 / std::max(1.0, residual_sum(pose) / dof);
  Vector6d prior_information;
  prior_information << Eigen::Vector3d::Constant(1.0 / (sigma_rad * sigma_rad)),
      Eigen::Vector3d::Constant(1.0 / (sigma_m * sigma_m));
  Pose current = pose;
  for (int iteration = 0; iteration < 5; ++iteration) {
    Matrix6d hessian = prior_information.asDiagonal();
    const Vector6d prior_error = motion_increment_between(expected, current, center_object);
    Vector6d gradient = prior_information.cwiseProduct(prior_error);
    const Eigen::Vector3d center_camera = current * center_object;
    for (std::size_t i = 0; i < points_object.size(); ++i) {
      const Eigen::Vector3d point_camera = current * points_object[i];
      if (!(point_camera.z() > 1e-6)) return pose;
      const Matrix26d jacobian =
          projection_jacobian(point_camera, center_camera, camera.fx(), camera.fy());
      const Eigen::Vector2d r = camera.project(point_camera) - points_image[i];
      hessian += inv_var_px * jacobian.transpose() * jacobian;
      gradient += inv_var_px * jacobian.transpose() * r;
    }
    const Vector6d step = hessian.ldlt().solve(-gradient);
    if (!step.allFinite()) return pose;
    current = apply_pose_increment(current, step, center_object);
    if (step.head<3>().norm() < 1e-6 && step.tail<3>().norm() < 1e-6) break;
  }
  return is_valid_pose(current) ? current : pose;
}

KeypointTracker::KeypointTracker(std::shared_ptr<const Mesh> mesh, const TrackerParams& params)
    : mesh_(mesh), renderer_(mesh), params_(params) {}

bool KeypointTracker::implausible_motion(const Pose& expected, const Pose& measured) const {
  if (params_.keypoint_max_motion_deg > 0.0) {
    const Eigen::AngleAxisd change(measured.linear() * expected.linear().transpose());
    if (std::abs(change.angle()) * 180.0 / M_PI > params_.keypoint_max_motion_deg) return true;
  }
  if (params_.keypoint_max_motion_diameters > 0.0 && diameter_m_ > 0.0) {
    const double moved_m = (measured * center_object_ - expected * center_object_).norm();
    if (moved_m > params_.keypoint_max_motion_diameters * diameter_m_) return true;
  }
  return false;
}

void KeypointTracker::clear() {
  previous_gray_.release();
  previous_source_size_ = cv::Size();
  previous_pyramid_.clear();
  object_mask_.release();
  image_points_.clear();
  object_points_.clear();
  detected_count_ = 0;
}

int KeypointTracker::detect(const cv::Mat& gray, const Pose& object_to_camera,
                            const PinholeCamera& camera, bool same_frame_as_track) {
  cv::Mat reused_klt_image;
  std::vector<cv::Mat> reused_pyramid;
  if (same_frame_as_track && previous_source_size_ == gray.size()) {
    reused_klt_image = previous_gray_;
    reused_pyramid = std::move(previous_pyramid_);
  }
  clear();
  // Large frames: corners are found (and later tracked) on the frame halved `steps` times;
  // they are anchored and stored in full-resolution pixels.
  const int steps = downscale_steps(gray.size());
  const double s = std::ldexp(1.0, -steps);
  const cv::Mat small = downscale(gray, steps);
  const PinholeCamera small_camera =
      steps == 0 ? camera
                 : PinholeCamera(camera.fx() * s, camera.fy() * s, camera.cx() * s,
                                 camera.cy() * s, small.cols, small.rows);
  RenderOptions options;
  options.draw_color = false;
  const RenderOutput render = renderer_.render(object_to_camera, small_camera, options);
  object_mask_ = render.mask();
  cv::Mat mask = object_mask_;
  // Corners on the silhouette mostly belong to the background (it shows through there) and
  // would be anchored on the wrong surface: the mask is eroded first (in the KLT frame's px).
  const int erosion = params_.keypoint_mask_erosion_px > 0
                          ? std::max(1, static_cast<int>(std::lround(
                                            params_.keypoint_mask_erosion_px * s)))
                          : 0;
  if (erosion > 0)
    cv::erode(object_mask_, mask,
              cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * erosion + 1, 2 * erosion + 1}));
  if (!reused_klt_image.empty()) {
    previous_gray_ = reused_klt_image;
    previous_pyramid_ = std::move(reused_pyramid);
  } else {
    previous_gray_ = klt_image(small);
  }
  previous_source_size_ = gray.size();
  if (cv::countNonZero(mask) == 0) return 0;

  // Shi-Tomasi on the mask's bounding box plus a margin, not the whole frame: the corner
  // response (3x3 Sobel, 3x3 block) inside the mask only sees pixels within 3 px of it, so the
  // corners are the same as on the whole frame (same values, same row-major tie order), at the
  // cost of the object's region only.
  constexpr int kCornerMarginPx = 8;
  const cv::Rect box = cv::boundingRect(mask);
  const cv::Rect crop = cv::Rect(box.x - kCornerMarginPx, box.y - kCornerMarginPx,
                                 box.width + 2 * kCornerMarginPx,
                                 box.height + 2 * kCornerMarginPx) &
                        cv::Rect(0, 0, small.cols, small.rows);
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(small(crop), corners, params_.max_keypoints,
                          params_.corner_quality_level, params_.corner_min_distance_px * s,
                          mask(crop));
  if (static_cast<int>(corners.size()) < params_.corner_fallback_below)
    cv::goodFeaturesToTrack(small(crop), corners, params_.max_keypoints,
                            params_.corner_fallback_quality_level, params_.corner_min_distance_px * s,
                            mask(crop));

  // Anchor each corner on the mesh (surface_anchor.h).
  for (const cv::Point2f& corner_in_crop : corners) {
    const cv::Point2f corner_small = corner_in_crop + cv::Point2f(crop.x, crop.y);
    // cv::pyrDown keeps pixel centres at integer coordinates: full = small / s.
    const cv::Point2f corner = corner_small * static_cast<float>(1.0 / s);
    Eigen::Vector3d point_object;
    if (!anchor_on_surface(render.face_index, corner_small, corner, *mesh_, object_to_camera,
                           camera, &point_object))
      continue;
    image_points_.push_back(corner);
    object_points_.emplace_back(static_cast<float>(point_object.x()),
                                static_cast<float>(point_object.y()),
                                static_cast<float>(point_object.z()));
  }
  detected_count_ = static_cast<int>(image_points_.size());
  return detected_count_;
}

int KeypointTracker::downscale_steps(const cv::Size& size) const {
  int steps = 0;
  if (params_.klt_max_image_width_px > 0)
    for (int width = size.width; width > params_.klt_max_image_width_px && steps < 4; ++steps)
      width = (width + 1) / 2;
  return steps;
}

cv::Mat KeypointTracker::downscale(const cv::Mat& gray, int steps) {
  cv::Mat small = gray;
  for (int i = 0; i < steps; ++i) cv::pyrDown(small, small);
  return small;
}

cv::Mat KeypointTracker::klt_image(const cv::Mat& gray) const {
  const int side = params_.klt_illumination_window_px;
  if (side <= 0) return gray.clone();
  // Local gain/offset normalization: (I - mean) / std over a side x side box. A lighting
  // change that is smooth over the window (a flash, a moving lamp) cancels out.
  cv::Mat intensity, mean, mean_of_squares;
  gray.convertTo(intensity, CV_32F);
  const cv::Size box(side, side);
  cv::boxFilter(intensity, mean, CV_32F, box);
  cv::boxFilter(intensity.mul(intensity), mean_of_squares, CV_32F, box);
  cv::Mat deviation;
  cv::sqrt(cv::max(mean_of_squares - mean.mul(mean), 0.0) + 16.0, deviation);  // >= 4 levels
  cv::Mat normalized;
  cv::Mat((intensity - mean) / deviation * 40.0 + 128.0).convertTo(normalized, CV_8U);
  return normalized;
}

bool KeypointTracker::needs_redetection() const {
  return detected_count_ == 0 ||
         static_cast<double>(image_points_.size()) < params_.redetect_ratio * detected_count_;
}

KeypointResult KeypointTracker::track(const cv::Mat& gray, const Pose& object_to_camera_guess,
                                      const PinholeCamera& camera,
                                      const KeypointPrediction* prediction) {
  KeypointResult result;
  const auto start = std::chrono::steady_clock::now();
  const int steps = downscale_steps(gray.size());
  const double s = std::ldexp(1.0, -steps);
  const cv::Mat small = downscale(gray, steps);
  if (image_points_.empty() || previous_gray_.empty() || previous_source_size_ != gray.size()) {
    previous_gray_ = klt_image(small);
    previous_source_size_ = gray.size();
    previous_pyramid_.clear();
    image_points_.clear();
    object_points_.clear();
    return result;
  }

  // Pyramidal Lucas-Kanade forward, then backward: a track is kept when it returns to
  // within klt_forward_backward_px of where it started.
  const cv::Size window(params_.klt_window_px, params_.klt_window_px);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  std::vector<cv::Mat> previous_pyramid = std::move(previous_pyramid_), current_pyramid;
  previous_pyramid_.clear();
  if (previous_pyramid.empty())
    cv::buildOpticalFlowPyramid(previous_gray_, previous_pyramid, window,
                                params_.klt_pyramid_levels);
  const cv::Mat current = klt_image(small);
  cv::buildOpticalFlowPyramid(current, current_pyramid, window, params_.klt_pyramid_levels);
  // Tracked on the (possibly halved) KLT frames; stored in full-resolution px.
  std::vector<cv::Point2f> start_points = image_points_;
  if (steps > 0)
    for (cv::Point2f& p : start_points) p *= static_cast<float>(s);
  std::vector<cv::Point2f> forward, backward;
  std::vector<uchar> status_forward, status_backward;
  std::vector<float> error;
  // Where the prediction puts each keypoint (behind the camera: where it was), full-res px.
  std::vector<cv::Point2f> predicted;
  if (prediction) {
    predicted.reserve(object_points_.size());
    for (std::size_t i = 0; i < object_points_.size(); ++i) {
      const cv::Point3f& p = object_points_[i];
      const Eigen::Vector3d q = prediction->object_to_camera * Eigen::Vector3d(p.x, p.y, p.z);
      if (q.z() > 1e-6) {
        const Eigen::Vector2d uv = camera.project(q);
        predicted.emplace_back(static_cast<float>(uv.x()), static_cast<float>(uv.y()));
      } else {
        predicted.push_back(image_points_[i]);
      }
    }
  }
  int flow_flags = 0;
  if (prediction && prediction->initial_flow) {
    forward = predicted;
    if (steps > 0)
      for (cv::Point2f& p : forward) p *= static_cast<float>(s);
    flow_flags = cv::OPTFLOW_USE_INITIAL_FLOW;
  }
  cv::calcOpticalFlowPyrLK(previous_pyramid, current_pyramid, start_points, forward,
                           status_forward, error, window, params_.klt_pyramid_levels, criteria,
                           flow_flags);
  backward = start_points;
  cv::calcOpticalFlowPyrLK(current_pyramid, previous_pyramid, forward, backward, status_backward,
                           error, window, params_.klt_pyramid_levels, criteria,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  if (steps > 0) {
    for (cv::Point2f& p : forward) p *= static_cast<float>(1.0 / s);
    for (cv::Point2f& p : backward) p *= static_cast<float>(1.0 / s);
  }

  std::vector<cv::Point2f> tracked_image;
  std::vector<cv::Point3f> tracked_object;
  std::vector<float> prediction_error_px;
  const double fb_limit_sq = params_.klt_forward_backward_px * params_.klt_forward_backward_px;
  for (size_t i = 0; i < image_points_.size(); ++i) {
    const cv::Point2f d = backward[i] - image_points_[i];
    if (!status_forward[i] || !status_backward[i] || d.dot(d) > fb_limit_sq) {
      // A track that failed with its LK window (at the predicted position, else the last one)
      // at the image border left the image: nothing covers the object there.
      const cv::Point2f& at = prediction ? predicted[i] : image_points_[i];
      if (camera.in_image({at.x, at.y}, params_.klt_window_px)) {
        const cv::Point3f& p = object_points_[i];
        result.lost_points_object.emplace_back(p.x, p.y, p.z);
      }
      continue;
    }
    if (!camera.in_image({forward[i].x, forward[i].y})) continue;
    tracked_image.push_back(forward[i]);
    tracked_object.push_back(object_points_[i]);
    if (prediction)
      prediction_error_px.push_back(static_cast<float>(cv::norm(forward[i] - predicted[i])));
  }
  // Tracks that disagree with the predicted motion (a background corner seen through the
  // outline, a wrong LK match) are dropped before RANSAC, unless most disagree.
  if (prediction && prediction->gate_px > 0.0) {
    std::vector<cv::Point2f> gated_image;
    std::vector<cv::Point3f> gated_object;
    for (std::size_t i = 0; i < tracked_image.size(); ++i)
      if (prediction_error_px[i] <= prediction->gate_px) {
        gated_image.push_back(tracked_image[i]);
        gated_object.push_back(tracked_object[i]);
      }
    if (2 * gated_image.size() >= tracked_image.size()) {
      tracked_image.swap(gated_image);
      tracked_object.swap(gated_object);
    }
  }
  previous_gray_ = current;
  previous_source_size_ = gray.size();
  previous_pyramid_ = std::move(current_pyramid);  // the next frame's previous pyramid
  image_points_ = tracked_image;
  object_points_ = tracked_object;
  result.tracked = static_cast<int>(tracked_image.size());
  result.klt_ms = elapsed_ms(start);
  if (result.tracked < std::max(params_.klt_min_points, 4)) return result;
  const auto pnp_start = std::chrono::steady_clock::now();

  cv::Mat rvec, tvec;
  pose_to_rvec_tvec(object_to_camera_guess, rvec, tvec);
  std::vector<int> inliers;
  const bool solved = cv::solvePnPRansac(
      tracked_object, tracked_image, camera.K(), cv::noArray(), rvec, tvec,
      /*useExtrinsicGuess=*/true, params_.ransac_iterations,
      static_cast<float>(params_.ransac_reprojection_px), 0.99, inliers, cv::SOLVEPNP_ITERATIVE);
  if (!solved || inliers.size() < 4) {
    result.pnp_ms = elapsed_ms(pnp_start);
    return result;
  }

  std::vector<cv::Point2f> inlier_image;
  std::vector<cv::Point3f> inlier_object;
  for (int i : inliers) {
    inlier_image.push_back(tracked_image[i]);
    inlier_object.push_back(tracked_object[i]);
  }
  // Levenberg-Marquardt on all inliers (RANSAC's estimate comes from its best subset).
  cv::solvePnPRefineLM(inlier_object, inlier_image, camera.K(), cv::noArray(), rvec, tvec);
  Pose pose = pose_from_rvec_tvec(rvec, tvec);
  std::vector<Eigen::Vector3d>& points_object = result.inlier_points.points_object;
  std::vector<Eigen::Vector2d>& points_image = result.inlier_points.points_image;
  for (size_t i = 0; i < inlier_image.size(); ++i) {
    points_object.emplace_back(inlier_object[i].x, inlier_object[i].y, inlier_object[i].z);
    points_image.emplace_back(inlier_image[i].x, inlier_image[i].y);
  }
  if (params_.keypoint_prior_diameters > 0.0 && diameter_m_ > 0.0 && is_valid_pose(pose))
    pose = pose_with_motion_prior(points_object, points_image, camera, pose,
                                  object_to_camera_guess, center_object_,
                                  params_.keypoint_prior_deg * M_PI / 180.0,
                                  params_.keypoint_prior_diameters * diameter_m_);

  result.inliers = static_cast<int>(inliers.size());
  result.inlier_ratio = static_cast<double>(result.inliers) / result.tracked;
  double error_sum = 0.0;
  for (size_t i = 0; i < points_object.size(); ++i)
    error_sum += (camera.project(pose * points_object[i]) - points_image[i]).norm();
  result.mean_reprojection_px = error_sum / points_object.size();

  const bool pose_ok = is_valid_pose(pose) && pose.translation().z() > 0;
  result.implausible_motion = pose_ok && implausible_motion(object_to_camera_guess, pose);
  result.success =
      pose_ok && !result.implausible_motion && result.inlier_ratio >= params_.klt_min_inlier_ratio;
  if (result.success) {
    result.object_to_camera = pose;
    // Outliers are dropped so they do not pollute the next frame's RANSAC.
    image_points_ = inlier_image;
    object_points_ = inlier_object;
  }
  result.pnp_ms = elapsed_ms(pnp_start);
  return result;
}

}  // namespace kct
