#pragma once
/// \file pose_cv.h
/// Pose <-> OpenCV's rotation vector + translation (cv::solvePnP's rvec, tvec; CV_64F 3x1), for
/// the PnP users (keypoint_tracker, feature_relocalizer). Kept out of pose.h, which needs Eigen only.

#include <opencv2/core.hpp>

#include "klt_contour_tracker/core/pose.h"

namespace kct {

/// The pose whose rotation is Rodrigues(rvec) and translation tvec.
Pose pose_from_rvec_tvec(const cv::Mat& rvec, const cv::Mat& tvec);

/// The rvec, tvec of `pose` (CV_64F 3x1 each).
void pose_to_rvec_tvec(const Pose& pose, cv::Mat& rvec, cv::Mat& tvec);

}  // namespace kct
