#include "klt_contour_tracker/core/basin_hopping.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

namespace kct {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kObjectSizeM = 0.2;

/// Mean squared distance (m^2) between the corners of a 20 cm cube placed at two poses: a
/// smooth measure of pose difference, like the misalignment a contour energy sees.
double mean_squared_corner_distance(const Pose& a, const Pose& b) {
  double sum = 0.0;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d corner(i & 1 ? 0.1 : -0.1, i & 2 ? 0.1 : -0.1, i & 4 ? 0.1 : -0.1);
    sum += (a * corner - b * corner).squaredNorm();
  }
  return sum / 8.0;
}

double bump(const Pose& pose, const Pose& peak, double width_m) {
  return std::exp(-mean_squared_corner_distance(pose, peak) / (width_m * width_m));
}

class BasinHoppingTest : public ::testing::Test {
 protected:
  BasinHoppingTest()
      : reference_(pose_from_quaternion(0.02, -0.01, 0.8, 0.1, 0.2, -0.05, 0.97)),
        param_(reference_, Eigen::Vector3d::Zero()),
        area_(make_extrapolated_search_area(kObjectSizeM, TrackerParams())) {
    settings_ = make_basin_hopping_settings(TrackerParams(), HopCounts{5, 3, 10}, kObjectSizeM);
    settings_.slsqp_max_evaluations = 400;
  }

  Pose reference_;
  PoseParametrization param_;
  SearchArea area_;
  BasinHoppingSettings settings_;
  BasinHoppingOptimizer optimizer_;
};

TEST_F(BasinHoppingTest, FindsSmoothPeakInsideTheBox) {
  Vector6d peak_x;
  peak_x << 5 * kDegToRad, -3 * kDegToRad, 8 * kDegToRad, 0.006, -0.004, 0.01;
  const Pose peak = param_.apply(peak_x);
  const auto energy = [&](const Pose& p) { return bump(p, peak, 0.05); };
  const OptimizationResult r = optimizer_.maximize(energy, param_, area_, settings_);
  EXPECT_LT(rotation_error_deg(r.best_pose, peak), 0.1);
  EXPECT_LT(translation_error(r.best_pose, peak), 1e-3);
  EXPECT_NEAR(r.best_energy, 1.0, 1e-6);
  EXPECT_NEAR(r.initial_energy, energy(reference_), 1e-15);
  EXPECT_LT(r.initial_energy, 0.8);
  EXPECT_TRUE(r.constraint_satisfied);
  EXPECT_LT((param_.apply(r.best_x).matrix() - r.best_pose.matrix()).norm(), 1e-12);
  EXPECT_TRUE(area_.box_contains(r.best_x));
}

TEST_F(BasinHoppingTest, FinalStageFromGivenStartRunsFixedHops) {
  Vector6d peak_x;
  peak_x << -4 * kDegToRad, 2 * kDegToRad, 6 * kDegToRad, -0.005, 0.003, 0.008;
  const Pose peak = param_.apply(peak_x);
  const auto energy = [&](const Pose& p) { return bump(p, peak, 0.05); };
  Vector6d start_x = peak_x;
  start_x(2) += 0.5 * kDegToRad;
  start_x(3) += 0.001;
  settings_.min_hops = settings_.max_hops = 5;
  settings_.max_hops_without_improvement = 1;
  const OptimizationResult r = optimizer_.maximize(energy, param_, area_, settings_, start_x);
  EXPECT_EQ(r.hops, 5);
  EXPECT_NEAR(r.initial_energy, energy(param_.apply(start_x)), 1e-15);
  EXPECT_LT(rotation_error_deg(r.best_pose, peak), 0.1);
  EXPECT_LT(translation_error(r.best_pose, peak), 1e-3);
  // Starting outside the box: the start is clipped onto it.
  Vector6d outside = Vector6d::Zero();
  outside(5) = 1.0;
  settings_.max_hops = 0;
  const OptimizationResult clipped = optimizer_.maximize(energy, param_, area_, settings_, outside);
  Vector6d on_box = Vector6d::Zero();
  on_box(5) = area_.upper(5);
  EXPECT_NEAR(clipped.initial_energy, energy(param_.apply(on_box)), 1e-15);
}

TEST_F(BasinHoppingTest, PeakOutsideTheBoxEndsOnTheBox) {
  Vector6d peak_x = Vector6d::Zero();
  peak_x(5) = 0.1;  // 10 cm along the camera axis; the box allows +-4 cm
  const Pose peak = param_.apply(peak_x);
  const OptimizationResult r = optimizer_.maximize(
      [&](const Pose& p) { return bump(p, peak, 0.1); }, param_, area_, settings_);
  EXPECT_NEAR(r.best_x(5), area_.upper(5), 1e-6);
  EXPECT_TRUE(area_.box_contains(r.best_x));
}

/// A broad local peak at the start (height 1) and a narrow global one (height 2) 12 deg and
/// 8 mm away: SLSQP alone stays in the broad one, basin hopping escapes to the narrow one.
class MultiModalTest : public BasinHoppingTest {
 protected:
  MultiModalTest() {
    Vector6d narrow_x = Vector6d::Zero();
    narrow_x(2) = 12 * kDegToRad;
    narrow_x(3) = 0.008;
    narrow_peak_ = param_.apply(narrow_x);
    energy_ = [this](const Pose& p) {
      return bump(p, reference_, 0.03) + 2.0 * bump(p, narrow_peak_, 0.012);
    };
    settings_.min_hops = 20;
    settings_.max_hops_without_improvement = 10;
    settings_.max_hops = 60;
    settings_.hop_rotation_rad = 8 * kDegToRad;
    settings_.hop_translation_m = 0.008;
  }
  bool in_narrow_peak(const OptimizationResult& r) const {
    return r.best_energy > 1.9 && rotation_error_deg(r.best_pose, narrow_peak_) < 1.0 &&
           translation_error(r.best_pose, narrow_peak_) < 1e-3;
  }
  Pose narrow_peak_;
  std::function<double(const Pose&)> energy_;
};

TEST_F(MultiModalTest, SingleSlsqpStaysInTheLocalPeak) {
  settings_.max_hops = 0;
  const OptimizationResult r = optimizer_.maximize(energy_, param_, area_, settings_);
  EXPECT_EQ(r.hops, 0);
  EXPECT_LT(r.best_energy, 1.1);
  EXPECT_GE(r.best_energy, r.initial_energy);
  EXPECT_LT(rotation_error_deg(r.best_pose, reference_), 1.0);
  EXPECT_FALSE(in_narrow_peak(r));
}

TEST_F(MultiModalTest, HoppingEscapesToTheGlobalPeak) {
  int found = 0;
  for (std::uint32_t seed = 1; seed <= 10; ++seed) {
    settings_.seed = seed;
    const OptimizationResult r = optimizer_.maximize(energy_, param_, area_, settings_);
    EXPECT_GE(r.best_energy, r.initial_energy);
    if (in_narrow_peak(r)) ++found;
  }
  EXPECT_GE(found, 9) << "seeds 1..10";
}

TEST_F(MultiModalTest, SameSeedSameResult) {
  settings_.seed = 7;
  const OptimizationResult a = optimizer_.maximize(energy_, param_, area_, settings_);
  const OptimizationResult b = optimizer_.maximize(energy_, param_, area_, settings_);
  EXPECT_EQ(a.best_x, b.best_x);
  EXPECT_EQ(a.best_energy, b.best_energy);
  EXPECT_EQ(a.hops, b.hops);
  EXPECT_EQ(a.evaluations, b.evaluations);
  settings_.seed = 8;
  const OptimizationResult c = optimizer_.maximize(energy_, param_, area_, settings_);
  EXPECT_NE(a.evaluations, c.evaluations);  // a different seed takes a different path
}

TEST_F(BasinHoppingTest, ReprojectionConstraintHolds) {
  const PinholeCamera camera(500.0, 500.0, 320.0, 240.0, 640, 480);
  std::vector<Eigen::Vector3d> points_object;
  std::vector<Eigen::Vector2d> points_image;
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector3d p(0.1 * std::sin(1.7 * i), 0.1 * std::cos(2.3 * i),
                            0.1 * std::sin(0.9 * i + 1.0));
    points_object.push_back(p);
    points_image.push_back(camera.project(reference_ * p) +
                           Eigen::Vector2d((i % 2) ? 0.7 : -0.7, (i % 3) ? 0.4 : -0.4));
  }
  const ReprojectionConstraint constraint(points_object, points_image, camera, reference_, 2.5);
  const SearchArea area = make_keypoint_search_area(kObjectSizeM, TrackerParams(), constraint);

  // The energy peaks 2 cm sideways and 3 deg off: ~12 px of reprojection error, infeasible.
  Vector6d peak_x = Vector6d::Zero();
  peak_x(3) = 0.02;
  peak_x(1) = 3 * kDegToRad;
  const Pose peak = param_.apply(peak_x);
  ASSERT_GT(constraint(peak), 5.0);
  const auto energy = [&](const Pose& p) { return bump(p, peak, 0.05); };

  const OptimizationResult r = optimizer_.maximize(energy, param_, area, settings_);
  EXPECT_TRUE(r.constraint_satisfied);
  EXPECT_LE(constraint(r.best_pose), 1e-6);
  EXPECT_NEAR(r.constraint_value, constraint(r.best_pose), 1e-12);
  EXPECT_GT(constraint(r.best_pose), -1e-3) << "the constrained optimum lies on the boundary";
  EXPECT_GT(r.best_energy, r.initial_energy);

  // No feasible point of a random cloud around the result beats it.
  std::mt19937 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  int feasible_samples = 0;
  for (int i = 0; i < 2000; ++i) {
    Vector6d x = r.best_x;
    for (int k = 0; k < 3; ++k) x(k) += 0.5 * kDegToRad * normal(rng);
    for (int k = 3; k < 6; ++k) x(k) += 0.001 * normal(rng);
    const Pose p = param_.apply(x);
    if (constraint(p) > 0.0 || !area.box_contains(x)) continue;
    ++feasible_samples;
    EXPECT_LE(energy(p), r.best_energy + 1e-9);
  }
  EXPECT_GT(feasible_samples, 100);
}

TEST_F(BasinHoppingTest, HopCountsAreRespected) {
  int calls = 0;
  const auto flat = [&](const Pose&) {
    ++calls;
    return 1.0;
  };
  struct Case {
    int min_hops, without_improvement, max_hops, expected;
  };
  // A flat energy never improves: the run stops at max(min_hops, without_improvement), capped.
  for (const Case& c : {Case{7, 3, 30, 7}, Case{2, 5, 30, 5}, Case{5, 5, 5, 5}, Case{5, 30, 5, 5},
                        Case{0, 1, 0, 0}}) {
    settings_.min_hops = c.min_hops;
    settings_.max_hops_without_improvement = c.without_improvement;
    settings_.max_hops = c.max_hops;
    calls = 0;
    const OptimizationResult r = optimizer_.maximize(flat, param_, area_, settings_);
    EXPECT_EQ(r.hops, c.expected) << c.min_hops << "/" << c.without_improvement << "/" << c.max_hops;
    EXPECT_EQ(r.evaluations, calls);
  }

  // An energy that grows with every call improves at every hop: the run goes to max_hops.
  settings_.min_hops = 2;
  settings_.max_hops_without_improvement = 1;
  settings_.max_hops = 12;
  settings_.slsqp_max_evaluations = 40;
  calls = 0;
  const auto growing = [&](const Pose&) { return static_cast<double>(++calls); };
  const OptimizationResult r = optimizer_.maximize(growing, param_, area_, settings_);
  EXPECT_EQ(r.hops, 12);
  EXPECT_EQ(r.evaluations, calls);
  // Per local optimization: 1 evaluation at the start point + at most the SLSQP budget.
  EXPECT_LE(r.evaluations, 13 * (1 + settings_.slsqp_max_evaluations));
}

TEST_F(BasinHoppingTest, LocalBudgetIsRespected) {
  Vector6d peak_x = Vector6d::Zero();
  peak_x(0) = 10 * kDegToRad;
  const Pose peak = param_.apply(peak_x);
  int calls = 0;
  const auto energy = [&](const Pose& p) {
    ++calls;
    return bump(p, peak, 0.05);
  };
  settings_.max_hops = 0;
  settings_.slsqp_max_evaluations = 30;  // two gradient evaluations (13 each) fit, not three
  const OptimizationResult r = optimizer_.maximize(energy, param_, area_, settings_);
  EXPECT_EQ(r.evaluations, calls);
  EXPECT_LE(calls, 1 + 30);
  EXPECT_GE(calls, 1 + 12);
  EXPECT_GE(r.best_energy, r.initial_energy);
}

TEST_F(BasinHoppingTest, RejectsBadSettings) {
  const auto energy = [](const Pose&) { return 0.0; };
  BasinHoppingSettings bad = settings_;
  bad.hop_rotation_rad = 0.0;
  EXPECT_THROW(optimizer_.maximize(energy, param_, area_, bad), std::invalid_argument);
  bad = settings_;
  bad.max_hops = -1;
  EXPECT_THROW(optimizer_.maximize(energy, param_, area_, bad), std::invalid_argument);
  SearchArea inverted = area_;
  inverted.lower(0) = 1.0;
  EXPECT_THROW(optimizer_.maximize(energy, param_, inverted, settings_), std::invalid_argument);
}

TEST_F(BasinHoppingTest, EnergyExceptionPropagates) {
  int calls = 0;
  const auto failing = [&](const Pose&) -> double {
    if (++calls == 5) throw std::domain_error("energy failed");
    return 1.0;
  };
  EXPECT_THROW(optimizer_.maximize(failing, param_, area_, settings_), std::domain_error);
}

TEST(MetropolisTest, Criterion) {
  EXPECT_TRUE(metropolis_accept(2.0, 1.0, 0.0, 0.999));   // improvement: always
  EXPECT_TRUE(metropolis_accept(1.0, 1.0, 0.0, 0.999));   // tie: accepted
  EXPECT_FALSE(metropolis_accept(0.9, 1.0, 0.0, 0.0));    // T = 0: never worse
  // T = 0.1 * |1.0| = 0.1; exp(-0.1 / 0.1) = 0.3679.
  EXPECT_TRUE(metropolis_accept(0.9, 1.0, 0.1, 0.36));
  EXPECT_FALSE(metropolis_accept(0.9, 1.0, 0.1, 0.37));
  // Negative energies: T uses |current| = 10 -> T = 1; exp(-1) = 0.3679.
  EXPECT_TRUE(metropolis_accept(-11.0, -10.0, 0.1, 0.36));
  EXPECT_FALSE(metropolis_accept(-11.0, -10.0, 0.1, 0.37));
  EXPECT_FALSE(metropolis_accept(-1.0, 0.0, 0.1, 0.0));  // current 0: T guarded to 0
}

TEST(BasinHoppingSettingsTest, FromTrackerParams) {
  TrackerParams params;
  const BasinHoppingSettings s = make_basin_hopping_settings(params, HopCounts{61, 30, 185}, 0.5);
  EXPECT_EQ(s.min_hops, 61);
  EXPECT_EQ(s.max_hops_without_improvement, 30);
  EXPECT_EQ(s.max_hops, 185);
  EXPECT_NEAR(s.hop_rotation_rad, params.hop_rotation_deg * kDegToRad, 1e-15);
  EXPECT_NEAR(s.hop_translation_m, params.hop_translation * 0.5, 1e-15);
  EXPECT_EQ(s.slsqp_max_evaluations, params.slsqp_max_evaluations);
  EXPECT_EQ(s.seed, params.random_seed);
  EXPECT_DOUBLE_EQ(s.temperature, params.metropolis_temperature);
}

}  // namespace
}  // namespace kct

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
