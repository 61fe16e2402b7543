#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "klt_contour_tracker/core/trajectory.h"

namespace {

const kct::PinholeCamera kCamera(525.0, 525.0, 319.5, 239.5, 640, 480);
const Eigen::Vector3d kCenter(0.0, 0.0, 0.0125);  // demo crate's bounding-box centre
constexpr double kDiameter = 0.156;

const kct::MotionGroup kGroups[] = {kct::MotionGroup::kFree,       kct::MotionGroup::kXY,
                                    kct::MotionGroup::kZ,          kct::MotionGroup::kInPlane,
                                    kct::MotionGroup::kOutOfPlane, kct::MotionGroup::kFlash,
                                    kct::MotionGroup::kMovingLight};

}  // namespace

TEST(SyntheticTrajectory, StaysInViewAndInRangeForEveryGroupAndSpeed) {
  for (kct::MotionGroup group : kGroups)
    for (int speed = 1; speed <= 5; ++speed) {
      kct::TrajectoryParams params;
      params.motion = group;
      params.speed = speed;
      params.seed = 11;
      const kct::SyntheticTrajectory trajectory(params, kCamera, kCenter, kDiameter);
      for (int i = 0; i < 600; ++i) {
        const kct::Pose pose = trajectory.frame_pose(i);
        ASSERT_TRUE(kct::is_valid_pose(pose));
        const Eigen::Vector3d c = pose * kCenter;
        ASSERT_GE(c.z(), params.distance_min_m - 1e-12);
        ASSERT_LE(c.z(), params.distance_max_m + 1e-12);
        // The whole bounding sphere projects inside the image.
        const Eigen::Vector2d p = kCamera.project(c);
        const double radius_px = 0.5 * kDiameter * kCamera.fx() / c.z();
        ASSERT_TRUE(kCamera.in_image(p, radius_px))
            << kct::to_string(group) << " speed " << speed << " frame " << i;
      }
    }
}

TEST(SyntheticTrajectory, DeterministicSmoothAndSpeedScaled) {
  kct::TrajectoryParams params;
  params.seed = 5;
  const kct::SyntheticTrajectory a(params, kCamera, kCenter, kDiameter);
  const kct::SyntheticTrajectory b(params, kCamera, kCenter, kDiameter);
  params.seed = 6;
  const kct::SyntheticTrajectory other(params, kCamera, kCenter, kDiameter);
  EXPECT_TRUE(a.frame_pose(17).isApprox(b.frame_pose(17), 0.0));
  EXPECT_GT(kct::rotation_error_deg(a.frame_pose(17), other.frame_pose(17)), 1.0);

  auto max_step_deg = [&](int speed) {
    kct::TrajectoryParams p;
    p.speed = speed;
    p.seed = 5;
    const kct::SyntheticTrajectory t(p, kCamera, kCenter, kDiameter);
    double largest = 0.0;
    for (int i = 1; i < 300; ++i)
      largest = std::max(largest, kct::rotation_error_deg(t.frame_pose(i - 1), t.frame_pose(i)));
    return largest;
  };
  const double slow = max_step_deg(1), fast = max_step_deg(5);
  EXPECT_GT(slow, 0.05);      // it moves
  EXPECT_LT(fast, 10.0);      // smooth: no jumps between consecutive frames at 30 Hz
  EXPECT_GT(fast, 3.0 * slow);  // speed 5 is about 5x faster than speed 1
}

TEST(SyntheticTrajectory, LightingGroupsVaryTheLight) {
  kct::TrajectoryParams params;
  params.motion = kct::MotionGroup::kFlash;
  const kct::SyntheticTrajectory flash(params, kCamera, kCenter, kDiameter);
  double lo = 1e9, hi = 0.0;
  for (int i = 0; i < 150; ++i) {
    lo = std::min(lo, flash.frame_lighting(i).light_gain);
    hi = std::max(hi, flash.frame_lighting(i).light_gain);
  }
  EXPECT_GT(hi / lo, 2.0);

  params.motion = kct::MotionGroup::kMovingLight;
  const kct::SyntheticTrajectory moving(params, kCamera, kCenter, kDiameter);
  const Eigen::Vector3d d0 = moving.frame_lighting(0).light_direction_camera.normalized();
  const Eigen::Vector3d d1 = moving.frame_lighting(60).light_direction_camera.normalized();
  EXPECT_LT(d0.dot(d1), 0.9);

  params.motion = kct::MotionGroup::kXY;
  const kct::SyntheticTrajectory still(params, kCamera, kCenter, kDiameter);
  EXPECT_EQ(still.frame_lighting(0).light_gain, still.frame_lighting(99).light_gain);
}

TEST(SyntheticTrajectory, NamesAndValidation) {
  for (kct::MotionGroup group : kGroups)
    EXPECT_EQ(kct::motion_group_from_string(kct::to_string(group)), group);
  EXPECT_THROW(kct::motion_group_from_string("sideways"), std::invalid_argument);
  kct::TrajectoryParams params;
  params.speed = 6;
  EXPECT_THROW(kct::SyntheticTrajectory(params, kCamera, kCenter, kDiameter),
               std::invalid_argument);
  params.speed = 3;
  EXPECT_THROW(kct::SyntheticTrajectory(params, kCamera, kCenter, 0.0), std::invalid_argument);
  // A 2 m object cannot fit at 0.35 m: the distance range is scaled up.
  const kct::SyntheticTrajectory big(params, kCamera, kCenter, 2.0);
  EXPECT_GT(big.distance_min_m(), 0.35);
  EXPECT_NEAR(big.distance_max_m() / big.distance_min_m(), 0.6 / 0.35, 1e-12);
}
