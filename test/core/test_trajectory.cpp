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

TEST(HandheldTrajectory, SpeedLimitsHoldJerksHappenAndItStaysInView) {
  kct::HandheldParams params;
  params.seed = 5;
  params.frames = 600;
  const kct::HandheldTrajectory trajectory(params, kCamera, kCenter, kDiameter);
  const double radius = 0.5 * kDiameter;
  double largest_step = 0.0, largest_turn = 0.0;
  int fast_frames = 0, direction_changes = 0;
  Eigen::Vector3d previous_step = Eigen::Vector3d::Zero();
  for (int i = 1; i <= params.frames; ++i) {
    const Eigen::Vector3d step = trajectory.frame_center_camera(i) - trajectory.frame_center_camera(i - 1);
    // The centre is where the pose puts the object's bounding-box centre.
    EXPECT_LT((trajectory.frame_pose(i) * kCenter - trajectory.frame_center_camera(i)).norm(), 1e-9);
    largest_step = std::max(largest_step, step.norm());
    largest_turn = std::max(largest_turn,
                            kct::rotation_error_deg(trajectory.frame_pose(i), trajectory.frame_pose(i - 1)));
    if (step.norm() > 0.015) ++fast_frames;
    if (previous_step.norm() > 0.005 && step.norm() > 0.005 && step.dot(previous_step) < 0.0)
      ++direction_changes;
    previous_step = step;
    const Eigen::Vector3d c = trajectory.frame_center_camera(i);
    const Eigen::Vector2d p = kCamera.project(c);
    const double r_px = radius * kCamera.fx() / c.z();
    EXPECT_GT(p.x() + 0.5 * r_px, 0.0) << "frame " << i;  // at least half of it in view
    EXPECT_LT(p.x() - 0.5 * r_px, kCamera.width()) << "frame " << i;
    EXPECT_GT(p.y() + 0.5 * r_px, 0.0) << "frame " << i;
    EXPECT_LT(p.y() - 0.5 * r_px, kCamera.height()) << "frame " << i;
  }
  EXPECT_LE(largest_step, 0.030 + 1e-9);
  EXPECT_LE(largest_turn, 8.0 + 1e-6);
  EXPECT_GT(largest_step, 0.02);  // the limits are reached, not only respected
  EXPECT_GT(largest_turn, 5.0);
  EXPECT_GT(fast_frames, 10);
  EXPECT_GT(direction_changes, 5);
}

TEST(HandheldTrajectory, DeterministicInterpolatedAndLeavesTheImageWhenAsked) {
  kct::HandheldParams params;
  params.seed = 9;
  params.frames = 90;
  params.leave_start_frame = 30;
  params.leave_frames = 15;
  const kct::HandheldTrajectory a(params, kCamera, kCenter, kDiameter);
  const kct::HandheldTrajectory b(params, kCamera, kCenter, kDiameter);
  for (int i = 0; i <= 90; ++i)
    EXPECT_TRUE(a.frame_pose(i).isApprox(b.frame_pose(i), 0.0)) << "frame " << i;
  // Half way between two frames: the centre is the midpoint.
  const Eigen::Vector3d mid = a.object_to_camera(10.5 / 30.0) * kCenter;
  EXPECT_LT((mid - 0.5 * (a.frame_center_camera(10) + a.frame_center_camera(11))).norm(), 1e-9);
  bool left = false;
  for (int i = 30; i < 50; ++i) {
    const Eigen::Vector2d p = kCamera.project(a.frame_center_camera(i));
    const double r_px = 0.5 * kDiameter * kCamera.fx() / a.frame_center_camera(i).z();
    left = left || p.x() + r_px < 0.0 || p.x() - r_px > kCamera.width();
  }
  EXPECT_TRUE(left);
  const Eigen::Vector2d back = kCamera.project(a.frame_center_camera(90));
  EXPECT_TRUE(kCamera.in_image(back)) << back.transpose();
  params.seed = 10;
  const kct::HandheldTrajectory other(params, kCamera, kCenter, kDiameter);
  EXPECT_FALSE(other.frame_pose(20).isApprox(a.frame_pose(20), 1e-6));
  params.max_translation_m = 0.0;
  EXPECT_THROW(kct::HandheldTrajectory(params, kCamera, kCenter, kDiameter), std::invalid_argument);
}
