#include "klt_contour_tracker/core/pose_cv.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

namespace kct {

Pose pose_from_rvec_tvec(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat rotation;
  cv::Rodrigues(rvec, rotation);
  Eigen::Matrix3d r;
  cv::cv2eigen(rotation, r);
  Pose pose = Pose::Identity();
  pose.linear() = r;
  pose.translation() = Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  return pose;
}

void pose_to_rvec_tvec(const Pose& pose, cv::Mat& rvec, cv::Mat& tvec) {
  cv::Mat rotation;
  cv::eigen2cv(Eigen::Matrix3d(pose.linear()), rotation);
  cv::Rodrigues(rotation, rvec);
  tvec = (cv::Mat_<double>(3, 1) << pose.translation().x(), pose.translation().y(),
          pose.translation().z());
}

}  // namespace kct
