// The pose-cost interface (pose increments, projection Jacobians, the weighted sum) and the
// contour cue's analytic gradient, on a rendered box view.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

#include "klt_contour_tracker/core/contour_cost.h"
#include "klt_contour_tracker/core/visibility_table.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

/// Central-difference gradient of `cost` w.r.t. the pose increment around `pose`.
Vector6d numeric_gradient(const PoseCost& cost, const Pose& pose, const Eigen::Vector3d& center,
                          double step_rad, double step_m) {
  Vector6d g;
  for (int i = 0; i < 6; ++i) {
    Vector6d d = Vector6d::Zero();
    d(i) = i < 3 ? step_rad : step_m;
    const double plus = cost.evaluate(apply_pose_increment(pose, d, center), nullptr, nullptr);
    const double minus = cost.evaluate(apply_pose_increment(pose, -d, center), nullptr, nullptr);
    g(i) = (plus - minus) / (2.0 * d(i));
  }
  return g;
}

TEST(PoseIncrement, ZeroIsIdentityAndRotationKeepsTheCentre) {
  const Pose pose = test::make_pose(0.5);
  const Eigen::Vector3d center(0.01, 0.02, -0.03);
  EXPECT_TRUE(apply_pose_increment(pose, Vector6d::Zero(), center).isApprox(pose, 1e-12));
  Vector6d rotate = Vector6d::Zero();
  rotate.head<3>() = Eigen::Vector3d(0.1, -0.2, 0.3);
  const Pose moved = apply_pose_increment(pose, rotate, center);
  EXPECT_LT((moved * center - pose * center).norm(), 1e-12);
  EXPECT_NEAR(rotation_error_deg(moved, pose), Eigen::Vector3d(0.1, -0.2, 0.3).norm() * 180 / M_PI,
              1e-9);
}

TEST(PoseIncrement, ProjectionJacobianMatchesFiniteDifferences) {
  const Pose pose = test::make_pose(0.5);
  const Eigen::Vector3d center(0.01, 0.02, -0.03), point(0.05, -0.04, 0.02);
  const PinholeCamera camera = test::make_camera();
  const Matrix26d j = projection_jacobian(pose * point, pose * center, camera.fx(), camera.fy());
  for (int i = 0; i < 6; ++i) {
    Vector6d d = Vector6d::Zero();
    d(i) = 1e-6;
    const Eigen::Vector2d numeric =
        (camera.project(apply_pose_increment(pose, d, center) * point) -
         camera.project(apply_pose_increment(pose, -d, center) * point)) / 2e-6;
    // Tolerance: 1e-4 relative (central differences, step 1e-6).
    EXPECT_LT((numeric - j.col(i)).norm(), 1e-4 * std::max(1.0, numeric.norm())) << "column " << i;
  }
}

/// A cue with a known quadratic cost, for the sum.
class QuadraticCue : public PoseCost {
 public:
  explicit QuadraticCue(double scale) : scale_(scale) {}
  std::string name() const override { return "quadratic"; }
  void begin_frame(const PoseCostFrame&) override { ++frames; }
  void linearize(const Pose&, int) override { ++linearizations; }
  double evaluate(const Pose& pose, Vector6d* gradient, Matrix6d* hessian) const override {
    const double x = pose.translation().x();
    if (gradient) (*gradient)(3) += 2 * scale_ * x;
    if (hessian) (*hessian)(3, 3) += 2 * scale_;
    return scale_ * x * x;
  }
  int frames = 0, linearizations = 0;

 private:
  double scale_;
};

TEST(PoseCostSum, WeightsEachCueAndSkipsZeroWeights) {
  auto a = std::make_shared<QuadraticCue>(1.0), b = std::make_shared<QuadraticCue>(10.0);
  PoseCostSum sum;
  sum.add(a, 2.0);
  sum.add(b, 0.0);
  EXPECT_THROW(sum.add(a, -1.0), std::invalid_argument);
  EXPECT_THROW(sum.add(nullptr, 1.0), std::invalid_argument);
  sum.begin_frame(PoseCostFrame());
  sum.linearize(Pose::Identity(), 0);
  EXPECT_EQ(a->frames, 1);
  EXPECT_EQ(b->frames, 0);
  Pose pose = Pose::Identity();
  pose.translation().x() = 3.0;
  Vector6d g;
  Matrix6d h;
  EXPECT_DOUBLE_EQ(sum.evaluate(pose, &g, &h), 18.0);
  EXPECT_DOUBLE_EQ(g(3), 12.0);
  EXPECT_DOUBLE_EQ(h(3, 3), 4.0);
}

/// The cost's analytic gradient at `pose` (0.45 m away) on the linearized `level` against
/// central differences with steps moving the contour by about 0.005 level px (few points cross
/// a pixel cell's border, where the bilinear interpolation's derivative jumps): within 2 % of the
/// gradient's norm (those crossings).
void expect_gradient_matches_numeric(const PoseCost& cost, const Pose& pose,
                                     const Eigen::Vector3d& center, const PinholeCamera& camera,
                                     int level, Matrix6d* hessian = nullptr) {
  Vector6d analytic = Vector6d::Zero();
  cost.evaluate(pose, &analytic, hessian);
  const double px_m = 0.45 / (camera.fx() * std::pow(0.5, level));
  const Vector6d numeric = numeric_gradient(cost, pose, center, 0.005 * px_m / 0.07, 0.005 * px_m);
  EXPECT_LT((analytic - numeric).norm(), 0.02 * numeric.norm())
      << "level " << level << "\nanalytic " << analytic.transpose() << "\nnumeric "
      << numeric.transpose();
}

class ContourCostTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto visibility = VisibilityTable::build(*mesh_, 2, 128, "");
    extractor_ = std::make_shared<ContourExtractor>(mesh_, visibility, 45.0);
    cv::Mat gray;
    cv::cvtColor(test::render_frame(renderer_, camera_, truth_, background_, 2.0, 1), gray,
                 cv::COLOR_BGR2GRAY);
    frame_.levels = make_pyramid(gray, camera_, 3);
    frame_.predicted_object_to_camera = frame_.preliminary_object_to_camera = truth_;
    frame_.center_object = mesh_->bounding_box_center();
  }

  std::shared_ptr<const Mesh> mesh_ = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Renderer renderer_{mesh_};
  PinholeCamera camera_ = test::make_camera();
  cv::Mat background_ = test::make_background(camera_.size(), 21, 32, 10, 60);
  Pose truth_ = test::make_pose(0.45);
  std::shared_ptr<const ContourExtractor> extractor_;
  PoseCostFrame frame_;
};

TEST_F(ContourCostTest, AnalyticGradientMatchesNumericOnEveryLevel) {
  ContourCost cost(extractor_, 2.0, 1.0);
  cost.begin_frame(frame_);
  // Off the optimum (where |g . n| has kinks), contour held fixed at the linearization.
  const Pose pose = test::move(truth_, 1.0, {0.3, 1.0, -0.2}, {0.0015, -0.001, 0.002});
  for (int level = 0; level < 3; ++level) {
    cost.linearize(pose, level);
    ASSERT_TRUE(cost.active());
    Matrix6d hessian = Matrix6d::Zero();
    expect_gradient_matches_numeric(cost, pose, frame_.center_object, camera_, level, &hessian);
    // The Hessian approximation is symmetric positive semi-definite.
    EXPECT_LT((hessian - hessian.transpose()).norm(), 1e-12 * hessian.norm());
    EXPECT_GE(Eigen::SelfAdjointEigenSolver<Matrix6d>(hessian).eigenvalues().minCoeff(),
              -1e-9 * hessian.norm());
  }
}

TEST_F(ContourCostTest, EnergyIsHighestAndCostLowestAtTheTruePose) {
  ContourCost cost(extractor_, 2.0, 1.0);
  cost.begin_frame(frame_);
  cost.linearize(truth_, 0);
  const Pose off = test::move(truth_, 2.0, {1, 0, 0}, {0.002, 0, 0});
  EXPECT_GT(cost.energy(truth_), 1.5 * cost.energy(off));
  EXPECT_LT(cost.evaluate(truth_, nullptr, nullptr), cost.evaluate(off, nullptr, nullptr));
  // About -1 at the true pose by construction of the contrast scale (within a factor 3).
  EXPECT_LT(cost.evaluate(truth_, nullptr, nullptr), -1.0 / 3.0);
  EXPECT_GT(cost.evaluate(truth_, nullptr, nullptr), -3.0);
}

TEST_F(ContourCostTest, AnotherFrameOfTheSameSizeAndRegionIsDifferentiatedAgain) {
  // begin_frame() keeps the last frame's derivatives when given the same pyramid and region
  // again (the session refines many hypotheses on one frame); a new frame must not get them.
  ContourCost cost(extractor_, 2.0, 1.0);
  cost.begin_frame(frame_);
  cost.linearize(truth_, 0);
  const double on_object = cost.energy(truth_);
  ASSERT_GT(on_object, 0.0);
  cv::Mat empty_gray(camera_.size(), CV_8UC1, cv::Scalar(90));  // nothing to see
  PoseCostFrame empty = frame_;
  empty.levels = make_pyramid(empty_gray, camera_, 3);
  cost.begin_frame(empty);
  cost.linearize(truth_, 0);
  EXPECT_LT(cost.energy(truth_), 1e-3 * on_object);
  // The first frame again (its pyramid rebuilt: new buffers), and the same pyramid twice.
  PoseCostFrame again = frame_;
  again.levels = make_pyramid(frame_.levels[0].gray.clone(), camera_, 3);
  for (int i = 0; i < 2; ++i) {
    cost.begin_frame(again);
    cost.linearize(truth_, 0);
    EXPECT_DOUBLE_EQ(cost.energy(truth_), on_object);
  }
}

TEST_F(ContourCostTest, ShiftedEnergiesAreTheEnergiesOfTheShiftedPoses) {
  ContourCost cost(extractor_, 2.0, 1.0);
  cost.begin_frame(frame_);
  const Pose pose = test::move(truth_, 1.0, {0.3, 1.0, -0.2}, {0.004, -0.003, 0.002});
  cost.linearize(pose, 2);
  // Shifts within the image and one taking most points out of the gradients' region.
  const std::vector<Eigen::Vector3d> shifts{
      {0.0, 0.0, 0.0}, {-0.004, 0.003, 0.0}, {0.01, 0.0, 0.0}, {0.0, -0.02, 0.0}, {2.0, 0.0, 0.0}};
  std::vector<int> counts;
  const std::vector<double> energies = cost.shifted_energies(pose, shifts, &counts);
  ASSERT_EQ(energies.size(), shifts.size());
  ASSERT_EQ(counts.size(), shifts.size());
  for (std::size_t i = 0; i < shifts.size(); ++i) {
    Pose shifted = pose;
    shifted.translation() += shifts[i];
    int count = 0;
    const double expected = cost.energy(shifted, &count);
    EXPECT_EQ(counts[i], count) << i;
    // The same sum, rounded differently (points moved before or after the shift).
    EXPECT_NEAR(energies[i], expected, 1e-9 * std::max(1.0, expected)) << i;
  }
  EXPECT_GT(counts[0], 0);
  EXPECT_EQ(counts[4], 0);  // 2 m aside: outside the image
  // The shift back to the truth scores higher than staying.
  EXPECT_GT(energies[1], energies[0]);
  // Only shifts parallel to the image plane.
  EXPECT_THROW(cost.shifted_energies(pose, {{0.0, 0.0, 0.01}}, &counts), std::invalid_argument);
}

TEST_F(ContourCostTest, PointsUnderTheOcclusionMaskAreLeftOut) {
  ContourCost cost(extractor_, 2.0, 1.0);
  cost.begin_frame(frame_);
  cost.linearize(truth_, 0);
  int all = 0;
  const double energy_all = cost.energy(truth_, &all);
  ASSERT_GT(all, 20);
  // The left half of the image masked: only the points on the right are counted, on every
  // level and by shifted_energies() alike.
  const Eigen::Vector2d center_px = camera_.project(truth_ * frame_.center_object);
  PoseCostFrame masked = frame_;
  masked.occlusion_mask = cv::Mat(camera_.size(), CV_8UC1, cv::Scalar(0));
  masked.occlusion_mask.colRange(0, static_cast<int>(center_px.x())).setTo(255);
  cost.begin_frame(masked);
  for (int level = 0; level < 3; ++level) {
    cost.linearize(truth_, level);
    int kept = 0;
    cost.energy(truth_, &kept);
    if (level == 0) {
      // A symmetric box seen about its centre: about half the points (20% tolerance).
      EXPECT_GT(kept, 0.3 * all);
      EXPECT_LT(kept, 0.7 * all);
      // Still the object's outline: the energy is the unmasked one's within 30%.
      EXPECT_NEAR(cost.energy(truth_), energy_all, 0.3 * energy_all);
    }
    std::vector<int> counts;
    cost.shifted_energies(truth_, {{0.0, 0.0, 0.0}}, &counts);
    EXPECT_EQ(counts[0], kept) << "level " << level;
  }
  // Everything masked: no point left.
  masked.occlusion_mask.setTo(255);
  cost.begin_frame(masked);
  cost.linearize(truth_, 0);
  int none = -1;
  EXPECT_EQ(cost.energy(truth_, &none), 0.0);
  EXPECT_EQ(none, 0);
}

TEST_F(ContourCostTest, ResultDoesNotDependOnTheThreadCount) {
  ContourCost one(extractor_, 2.0, 1.0, 1), two(extractor_, 2.0, 1.0, 2);
  one.begin_frame(frame_);
  two.begin_frame(frame_);
  const Pose pose = test::move(truth_, 1.0, {0.3, 1.0, -0.2}, {0.0015, -0.001, 0.002});
  for (int level = 0; level < 3; ++level) {
    one.linearize(pose, level);
    two.linearize(pose, level);
    Vector6d g1 = Vector6d::Zero(), g2 = Vector6d::Zero();
    EXPECT_EQ(one.evaluate(pose, &g1, nullptr), two.evaluate(pose, &g2, nullptr));
    EXPECT_EQ(g1, g2);
  }
}

TEST(Chromaticity, IgnoresShadingAndFollowsHue) {
  // Orange at full and at 40 % brightness, and blue of the dark orange's grey level.
  cv::Mat bgr(1, 3, CV_8UC3);
  bgr.at<cv::Vec3b>(0, 0) = {20, 110, 220};
  bgr.at<cv::Vec3b>(0, 1) = {8, 44, 88};
  bgr.at<cv::Vec3b>(0, 2) = {110, 50, 20};
  const cv::Mat chroma = chromaticity(bgr);
  ASSERT_EQ(chroma.type(), CV_32FC2);
  const cv::Vec2f bright = chroma.at<cv::Vec2f>(0, 0), dark = chroma.at<cv::Vec2f>(0, 1),
                  blue = chroma.at<cv::Vec2f>(0, 2);
  // The shading moves it by the dark offset's share only (< 20 % here); the hue by > 100.
  EXPECT_LT(cv::norm(bright - dark), 0.2 * cv::norm(bright));
  EXPECT_GT(cv::norm(dark - blue), 100.0);
  // Grey has none.
  const cv::Mat grey(2, 2, CV_8UC3, cv::Scalar(90, 90, 90));
  EXPECT_LT(cv::norm(chromaticity(grey), cv::NORM_INF), 1e-4);
  EXPECT_THROW(chromaticity(cv::Mat(2, 2, CV_8UC1, cv::Scalar(0))), std::invalid_argument);
}

/// An orange box whose shading darkens over the last 6 px inside its outline (a curved
/// object's rim), on a blue background of the dark rim's grey level: the outline is an edge
/// of colour only, the strongest grey edge is inside the object.
class ShadedRimTest : public ContourCostTest {
 protected:
  void SetUp() override {
    ContourCostTest::SetUp();
    const cv::Mat mask = renderer_.render(truth_, camera_).mask();
    cv::Mat inside;
    cv::distanceTransform(mask, inside, cv::DIST_L2, 3);
    cv::Mat bgr(camera_.size(), CV_8UC3, cv::Scalar(110, 50, 20));
    for (int v = 0; v < bgr.rows; ++v)
      for (int u = 0; u < bgr.cols; ++u)
        if (mask.at<uchar>(v, u)) {
          const double shade = 0.4 + 0.6 * std::min(1.0, (inside.at<float>(v, u) - 1.0) / 6.0);
          bgr.at<cv::Vec3b>(v, u) =
              cv::Vec3b(cv::saturate_cast<uchar>(20 * shade), cv::saturate_cast<uchar>(110 * shade),
                        cv::saturate_cast<uchar>(220 * shade));
        }
    cv::Mat gray;
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    gray_ = gray;
    shaded_.levels = make_pyramid(gray_, camera_, 3, bgr);
    shaded_.predicted_object_to_camera = shaded_.preliminary_object_to_camera = truth_;
    shaded_.center_object = frame_.center_object;
  }
  /// The energy at the true pose and at the pose 4 % farther (its outline ~3 px inside).
  std::pair<double, double> truth_and_farther(double chroma_weight) {
    ContourCost cost(extractor_, 2.0, 1.0, 1, chroma_weight);
    cost.begin_frame(shaded_);
    cost.linearize(truth_, 0);
    Pose farther = truth_;
    farther.translation() *= 1.04;
    return {cost.energy(truth_), cost.energy(farther)};
  }
  cv::Mat gray_;
  PoseCostFrame shaded_;
};

TEST_F(ShadedRimTest, GreyEdgesPullTheOutlineInsideAndChromaticityHoldsIt) {
  const auto [grey_truth, grey_farther] = truth_and_farther(0.0);
  EXPECT_GT(grey_farther, grey_truth);  // the bias this cue is for
  const auto [chroma_truth, chroma_farther] = truth_and_farther(1.0);
  EXPECT_GT(chroma_truth, 1.1 * chroma_farther);
  // Grey levels alone (no colour frame given): the weight changes nothing.
  PoseCostFrame grey_only = shaded_;
  grey_only.levels = make_pyramid(gray_, camera_, 3);
  ContourCost plain(extractor_, 2.0, 1.0), weighted(extractor_, 2.0, 1.0, 1, 1.0);
  plain.begin_frame(grey_only);
  weighted.begin_frame(grey_only);
  plain.linearize(truth_, 0);
  weighted.linearize(truth_, 0);
  EXPECT_EQ(plain.energy(truth_), weighted.energy(truth_));
}

TEST_F(ShadedRimTest, AnalyticGradientWithChromaticityMatchesNumericOnEveryLevel) {
  ContourCost cost(extractor_, 2.0, 1.0, 1, 1.0);
  cost.begin_frame(shaded_);
  const Pose pose = test::move(truth_, 1.0, {0.3, 1.0, -0.2}, {0.0015, -0.001, 0.002});
  for (int level = 0; level < 3; ++level) {
    cost.linearize(pose, level);
    ASSERT_TRUE(cost.active());
    expect_gradient_matches_numeric(cost, pose, shaded_.center_object, camera_, level);
  }
  // Shifted energies read the chromaticity too.
  cost.linearize(pose, 1);
  std::vector<int> counts;
  const std::vector<Eigen::Vector3d> shifts{{0.002, -0.001, 0.0}};
  Pose shifted = pose;
  shifted.translation() += shifts[0];
  EXPECT_NEAR(cost.shifted_energies(pose, shifts, &counts)[0], cost.energy(shifted),
              1e-9 * cost.energy(shifted));
}

TEST(ContourCost, RejectsBadSettings) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.1, 0.1, 0.1, false));
  auto extractor = std::make_shared<ContourExtractor>(mesh, nullptr, 45.0);
  EXPECT_THROW(ContourCost(nullptr, 2.0, 1.0), std::invalid_argument);
  EXPECT_THROW(ContourCost(extractor, 0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(ContourCost(extractor, 2.0, -1.0), std::invalid_argument);
  EXPECT_THROW(ContourCost(extractor, 2.0, 1.0, 0), std::invalid_argument);
  EXPECT_THROW(ContourCost(extractor, 2.0, 1.0, 1, -0.5), std::invalid_argument);
}

}  // namespace
}  // namespace kct
