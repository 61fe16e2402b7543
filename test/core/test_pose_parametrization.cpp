#include "klt_contour_tracker/core/pose_parametrization.h"

#include <gtest/gtest.h>

#include <cmath>

namespace kct {
namespace {

Pose reference_pose() {
  return pose_from_quaternion(0.05, -0.02, 0.6, 0.3, -0.2, 0.1, 0.9);
}

const Eigen::Vector3d kCenterObject(0.03, -0.01, 0.05);

TEST(PoseParametrization, ZeroGivesReferenceExactly) {
  const Pose reference = reference_pose();
  const PoseParametrization param(reference, kCenterObject);
  const Pose pose = param.apply(Vector6d::Zero());
  EXPECT_LT((pose.matrix() - reference.matrix()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(PoseParametrization, RotationKeepsCenterFixedInCamera) {
  const Pose reference = reference_pose();
  const PoseParametrization param(reference, kCenterObject);
  const Eigen::Vector3d center_camera = reference * kCenterObject;
  for (int axis = 0; axis < 3; ++axis) {
    Vector6d x = Vector6d::Zero();
    x(axis) = 0.4;
    const Pose pose = param.apply(x);
    EXPECT_LT((pose * kCenterObject - center_camera).norm(), 1e-12) << "axis " << axis;
    EXPECT_NEAR(rotation_error_deg(pose, reference), 0.4 * 180.0 / M_PI, 1e-9);
    // The rotation is about the camera-frame axis: that axis is unchanged by the delta.
    const Eigen::Matrix3d delta = pose.linear() * reference.linear().transpose();
    EXPECT_LT((delta.col(axis) - Eigen::Vector3d::Unit(axis)).norm(), 1e-12);
  }
  // All three angles together: the centre still stays.
  Vector6d x;
  x << 0.2, -0.3, 0.5, 0, 0, 0;
  EXPECT_LT((param.apply(x) * kCenterObject - center_camera).norm(), 1e-12);
}

TEST(PoseParametrization, TranslationMovesCenterByExactlyT) {
  const Pose reference = reference_pose();
  const PoseParametrization param(reference, kCenterObject);
  Vector6d x;
  x << 0.1, -0.2, 0.3, 0.012, -0.034, 0.056;
  const Pose pose = param.apply(x);
  const Eigen::Vector3d moved = pose * kCenterObject - reference * kCenterObject;
  EXPECT_LT((moved - x.tail<3>()).norm(), 1e-12);
  // Pure translation: the rotation is untouched and every point moves by t.
  Vector6d t = Vector6d::Zero();
  t.tail<3>() << 0.01, 0.02, -0.03;
  const Pose shifted = param.apply(t);
  EXPECT_LT((shifted.linear() - reference.linear()).norm(), 1e-15);
  const Eigen::Vector3d p(0.2, 0.1, -0.3);
  EXPECT_LT((shifted * p - reference * p - t.tail<3>()).norm(), 1e-12);
}

TEST(PoseParametrization, ParametersOfInvertsApply) {
  const PoseParametrization param(reference_pose(), kCenterObject);
  Vector6d x;
  x << 0.3, -0.5, 1.2, 0.02, 0.01, -0.05;
  const Vector6d back = param.parameters_of(param.apply(x));
  EXPECT_LT((back - x).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_TRUE(is_valid_pose(param.apply(x)));
}

}  // namespace
}  // namespace kct

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
