#include "klt_contour_tracker/core/search_area.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace kct {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

struct HopCase {
  std::size_t vertices, faces;
  int min_hops, without_improvement, max_hops;
};

TEST(HopCounts, PaperObjectsAndCaps) {
  const TrackerParams params;  // paper: budget 25000, caps 100 / 30 / 200
  const HopCase cases[] = {
      {1448, 2594, 61, 30, 185},      // House: s = 25000 / 4042 = 6.185
      {3394, 6788, 24, 12, 73},       // Soda: s = 2.455
      {5763, 11496, 14, 7, 43},       // Ironman: s = 1.449
      {14398, 28648, 10, 5, 30},      // Chest: s = 1
      {78562, 156950, 10, 5, 30},     // Bike: s = 1
      {88730, 176260, 10, 5, 30},     // Jet: s = 1
      {8, 12, 100, 30, 200},          // a cube: every cap applies
      {1250, 1250, 100, 30, 200},     // s = 10 exactly: 10 s = 100 not rounded down to 99
      {3750, 3750, 33, 16, 100},      // s = 3.333: 30 s = 100 exactly
  };
  for (const HopCase& c : cases) {
    const HopCounts counts = hop_counts(c.vertices, c.faces, params);
    EXPECT_EQ(counts.min_hops, c.min_hops) << c.vertices << "+" << c.faces;
    EXPECT_EQ(counts.max_hops_without_improvement, c.without_improvement)
        << c.vertices << "+" << c.faces;
    EXPECT_EQ(counts.max_hops, c.max_hops) << c.vertices << "+" << c.faces;
  }
}

TEST(HopCounts, FollowsParams) {
  TrackerParams params;
  params.hops_budget = 1000.0;
  params.min_hops_cap = 7;
  const HopCounts counts = hop_counts(100, 150, params);  // s = 4
  EXPECT_EQ(counts.min_hops, 7);
  EXPECT_EQ(counts.max_hops_without_improvement, 20);
  EXPECT_EQ(counts.max_hops, 120);
  params.max_hops_cap = 0;  // degenerate cap: still at least one hop
  EXPECT_EQ(hop_counts(100, 150, params).max_hops, 1);
}

TEST(SearchArea, ExtrapolatedBox) {
  const TrackerParams params;  // paper: 30 deg, 0.2 axial, 0.1 lateral
  const SearchArea area = make_extrapolated_search_area(0.5, params);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(area.upper(i), 30.0 * kDegToRad, 1e-12);
    EXPECT_NEAR(area.lower(i), -30.0 * kDegToRad, 1e-12);
  }
  EXPECT_NEAR(area.upper(3), 0.05, 1e-12);
  EXPECT_NEAR(area.upper(4), 0.05, 1e-12);
  EXPECT_NEAR(area.upper(5), 0.1, 1e-12);
  EXPECT_NEAR(area.lower(3), -0.05, 1e-12);
  EXPECT_NEAR(area.lower(5), -0.1, 1e-12);
  EXPECT_FALSE(area.has_constraint());
  EXPECT_TRUE(area.box_contains(Vector6d::Zero()));
  Vector6d outside = Vector6d::Zero();
  outside(5) = 0.11;
  EXPECT_FALSE(area.box_contains(outside));
  EXPECT_THROW(make_extrapolated_search_area(0.0, params), std::invalid_argument);
}

class ReprojectionConstraintTest : public ::testing::Test {
 protected:
  ReprojectionConstraintTest()
      : camera_(500.0, 500.0, 320.0, 240.0, 640, 480),
        pnp_pose_(pose_from_quaternion(0.01, -0.02, 0.8, 0.1, 0.2, -0.05, 0.97)) {
    // A 20 cm object; observations = projections at P~ plus a fixed +-1 px pattern, so the
    // error at P~ is about 1 px (not zero, as after a real PnP).
    for (int i = 0; i < 30; ++i) {
      const Eigen::Vector3d p(0.1 * std::sin(1.7 * i), 0.1 * std::cos(2.3 * i),
                              0.1 * std::sin(0.9 * i + 1.0));
      points_object_.push_back(p);
      const Eigen::Vector2d noise((i % 2) ? 1.0 : -1.0, (i % 3) ? 0.5 : -0.5);
      points_image_.push_back(camera_.project(pnp_pose_ * p) + noise);
    }
  }
  PinholeCamera camera_;
  Pose pnp_pose_;
  std::vector<Eigen::Vector3d> points_object_;
  std::vector<Eigen::Vector2d> points_image_;
};

TEST_F(ReprojectionConstraintTest, AverageErrorIsMeanEuclideanDistance) {
  const ReprojectionConstraint constraint(points_object_, points_image_, camera_, pnp_pose_, 2.5);
  EXPECT_NEAR(constraint.average_error_px(pnp_pose_), std::hypot(1.0, 0.5), 1e-9);
  EXPECT_NEAR(constraint.reference_error_px(), std::hypot(1.0, 0.5), 1e-9);
}

TEST_F(ReprojectionConstraintTest, MinusEmaxAtPnpPoseAndPositiveFarAway) {
  const ReprojectionConstraint constraint(points_object_, points_image_, camera_, pnp_pose_, 2.5);
  EXPECT_NEAR(constraint(pnp_pose_), -2.5, 1e-12);
  const PoseParametrization param(pnp_pose_, Eigen::Vector3d::Zero());
  Vector6d x = Vector6d::Zero();
  x(3) = 0.05;  // 5 cm sideways at 0.8 m: ~31 px
  EXPECT_GT(constraint(param.apply(x)), 20.0);
  x.setZero();
  x(2) = 20.0 * kDegToRad;
  EXPECT_GT(constraint(param.apply(x)), 0.0);
  // A tiny move stays feasible.
  x.setZero();
  x(4) = 0.0005;  // ~0.3 px
  EXPECT_LT(constraint(param.apply(x)), 0.0);
  // Behind the camera: finite and infeasible.
  x.setZero();
  x(5) = -1.0;
  const double behind = constraint(param.apply(x));
  EXPECT_TRUE(std::isfinite(behind));
  EXPECT_GT(behind, 0.0);
}

TEST_F(ReprojectionConstraintTest, KeypointSearchArea) {
  const TrackerParams params;
  const SearchArea area = make_keypoint_search_area(
      0.2, params, ReprojectionConstraint(points_object_, points_image_, camera_, pnp_pose_, 2.5));
  ASSERT_TRUE(area.has_constraint());
  EXPECT_NEAR(area.constraint(pnp_pose_), -2.5, 1e-12);
  const SearchArea extrapolated = make_extrapolated_search_area(0.2, params);
  EXPECT_LT((area.upper - 2.0 * extrapolated.upper).norm(), 1e-12);
  EXPECT_LT((area.lower + area.upper).norm(), 1e-12);
  EXPECT_THROW(ReprojectionConstraint({}, {}, camera_, pnp_pose_, 2.5), std::invalid_argument);
  EXPECT_THROW(ReprojectionConstraint(points_object_, points_image_, camera_, pnp_pose_, -1.0),
               std::invalid_argument);
}

}  // namespace
}  // namespace kct

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
