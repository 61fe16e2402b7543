#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "klt_contour_tracker/core/contour_energy.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

GradientImage gradient_of(const cv::Mat& bgr, double sigma) {
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  return GradientImage::compute(gray, sigma);
}

/// One of the 6 pose parameters: rotation about a camera axis through the object origin or
/// translation along a camera axis.
Pose perturb(const Pose& pose, int parameter, double amount) {
  const Eigen::Vector3d axis = Eigen::Vector3d::Unit(parameter % 3);
  return parameter < 3 ? test::move(pose, amount, axis, Eigen::Vector3d::Zero())
                       : test::move(pose, 0.0, axis, amount * axis);
}

struct Slice {
  std::vector<double> energy;
  int argmax() const {
    return static_cast<int>(std::max_element(energy.begin(), energy.end()) - energy.begin());
  }
  int local_maxima() const {
    int count = 0;
    for (std::size_t i = 1; i + 1 < energy.size(); ++i)
      count += energy[i] > energy[i - 1] && energy[i] > energy[i + 1];
    return count;
  }
};

/// Energies at truth + k * step, k = -half_steps..half_steps, for `parameter`.
Slice slice(const ContourEnergy& energy, const PinholeCamera& camera, const GradientImage& g,
            const Pose& truth, int parameter, double step, int half_steps) {
  Slice s;
  for (int k = -half_steps; k <= half_steps; ++k)
    s.energy.push_back(energy.evaluate(perturb(truth, parameter, k * step), camera, g));
  return s;
}

class ContourEnergyScene : public ::testing::TestWithParam<bool> {
 protected:
  void SetUp() override {
    mesh_ = std::make_shared<Mesh>(test::make_box(0.10, 0.08, 0.06, /*textured=*/GetParam()));
    table_ = VisibilityTable::build(*mesh_, 3, 128, "");
    camera_ = test::make_camera();
    truth_ = test::make_pose(0.45);
    const Renderer renderer(mesh_);
    frame_ = test::render_frame(renderer, camera_, truth_,
                                test::make_background(camera_.size(), 5), 4.0, 9);
  }
  std::shared_ptr<Mesh> mesh_;
  std::shared_ptr<const VisibilityTable> table_;
  PinholeCamera camera_;
  Pose truth_;
  cv::Mat frame_;
};

// Paper Fig. 2: along 1-D slices through the true pose the energy peaks at the true pose.
TEST_P(ContourEnergyScene, SlicesPeakAtTruePose) {
  const ContourEnergy energy(mesh_, table_, 45.0, 2.0);
  const double size = mesh_->diameter();
  for (double sigma : {0.0, 1.1}) {
    const GradientImage g = gradient_of(frame_, sigma);
    EXPECT_GT(energy.evaluate(truth_, camera_, g), 5.0);
    for (int parameter = 0; parameter < 6; ++parameter) {
      const double step = parameter < 3 ? 1.0 : 0.01 * size;  // 1 deg or 1 % of the size
      const Slice s = slice(energy, camera_, g, truth_, parameter, step, 10 * (parameter < 3) +
                                                                       5 * (parameter >= 3));
      const int centre = static_cast<int>(s.energy.size()) / 2;
      EXPECT_LE(std::abs(s.argmax() - centre), 1)
          << "sigma " << sigma << " parameter " << parameter << " argmax " << s.argmax();
    }
  }
}

TEST_P(ContourEnergyScene, BlurSmoothsSlices) {
  const ContourEnergy energy(mesh_, table_, 45.0, 2.0);
  const double size = mesh_->diameter();
  const GradientImage sharp = gradient_of(frame_, 0.0), blurred = gradient_of(frame_, 1.1);
  int maxima_sharp = 0, maxima_blurred = 0;
  for (int parameter = 0; parameter < 6; ++parameter) {
    const double step = parameter < 3 ? 0.5 : 0.0025 * size;  // +-10 deg, +-5 % of the size
    const Slice a = slice(energy, camera_, sharp, truth_, parameter, step, 20);
    const Slice b = slice(energy, camera_, blurred, truth_, parameter, step, 20);
    maxima_sharp += a.local_maxima();
    maxima_blurred += b.local_maxima();
    EXPECT_LE(std::abs(b.argmax() - 20), 2) << "parameter " << parameter;
  }
  EXPECT_LE(maxima_blurred, maxima_sharp);
}

INSTANTIATE_TEST_SUITE_P(PlainAndTextured, ContourEnergyScene, ::testing::Values(false, true));

TEST(GradientImage, SobelScaleIsIntensityPerPixel) {
  cv::Mat ramp(40, 50, CV_8UC1);
  for (int y = 0; y < ramp.rows; ++y)
    for (int x = 0; x < ramp.cols; ++x) ramp.at<std::uint8_t>(y, x) = 3 * x + 2 * y;
  const GradientImage g = GradientImage::compute(ramp, 0.0);
  ASSERT_EQ(g.gx.type(), CV_32FC1);
  for (int y = 1; y < ramp.rows - 1; ++y)
    for (int x = 1; x < ramp.cols - 1; ++x) {
      EXPECT_FLOAT_EQ(g.gx.at<float>(y, x), 3.0f);
      EXPECT_FLOAT_EQ(g.gy.at<float>(y, x), 2.0f);
    }
  const GradientImage blurred = GradientImage::compute(ramp, 1.1);  // a ramp stays a ramp
  EXPECT_NEAR(blurred.gx.at<float>(20, 25), 3.0f, 1e-4);
  EXPECT_THROW(GradientImage::compute(cv::Mat(), 0.0), std::invalid_argument);
  EXPECT_THROW(GradientImage::compute(cv::Mat(4, 4, CV_64FC2), 0.0), std::invalid_argument);
}

TEST(ContourEnergy, StepEdgeGivesHalfTheStep) {
  // Face-on cube: the contour is the outline of a square. Paint exactly the pixels whose
  // centres lie inside it with 120 on a background of 20: across each straight edge the
  // Sobel gradient is 100 / 2 on the two pixels straddling it, so |grad . n| = 50 along the
  // edges (less only within ~1 px of the corners).
  auto mesh = std::make_shared<Mesh>(test::make_box(0.1, 0.1, 0.1, false));
  const PinholeCamera camera = test::make_camera();
  Pose pose = Pose::Identity();
  pose.translation() = Eigen::Vector3d(0.003, -0.002, 0.5);
  const ContourEnergy energy(mesh, nullptr, 45.0, 2.0);
  const double half_px = 0.05 * 600.0 / 0.45;
  const double cx = 319.5 + 600.0 * 0.003 / 0.45, cy = 239.5 - 600.0 * 0.002 / 0.45;
  cv::Mat image(480, 640, CV_8UC1, cv::Scalar(20));
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x)
      if (std::abs(x - cx) < half_px && std::abs(y - cy) < half_px)
        image.at<std::uint8_t>(y, x) = 120;
  const GradientImage g = GradientImage::compute(image, 0.0);
  const EnergyDetails details = energy.evaluate_details(pose, camera, g);
  ASSERT_EQ(details.segments.size(), 4u);
  // 4 sides of 2 * half_px = 133.3 px at 2 px spacing: round(66.7) = 67 points each.
  EXPECT_EQ(details.num_points, 4 * 67);
  std::vector<double> values = details.values;
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  EXPECT_NEAR(values[values.size() / 2], 50.0, 1e-4);
  EXPECT_GT(details.energy, 48.0);
  EXPECT_LE(details.energy, 50.0 + 1e-9);
  EXPECT_DOUBLE_EQ(energy.evaluate(pose, camera, g), details.energy);
  // Moved away so that the outline shrinks by 3 px: the Sobel support misses the step.
  Pose off = pose;
  off.translation().z() = 0.05 + 0.05 * 600.0 / (half_px - 3.0);
  EXPECT_LT(energy.evaluate(off, camera, g), 1e-6);
}

TEST(ContourEnergy, PointsOutsideTheImageAreDropped) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.10, 0.08, 0.06, false));
  const auto table = VisibilityTable::build(*mesh, 3, 128, "");
  const PinholeCamera camera = test::make_camera();
  Pose pose = test::make_pose(0.45);
  pose.translation().x() = -319.5 / 600.0 * 0.45;  // object centre on the left border
  const Renderer renderer(mesh);
  const cv::Mat frame =
      test::render_frame(renderer, camera, pose, test::make_background(camera.size(), 5), 4.0);
  const GradientImage g = gradient_of(frame, 1.1);
  const ContourEnergy energy(mesh, table, 45.0, 2.0);
  const EnergyDetails details = energy.evaluate_details(pose, camera, g);

  // By hand: the same points, bilinear interpolation written out, only the inside ones.
  double sum = 0.0;
  int inside = 0, total = 0;
  for (const ContourSegment& s : details.segments) {
    const Eigen::Vector2d d = s.b_px - s.a_px;
    const int n = std::max(1, static_cast<int>(std::lround(d.norm() / 2.0)));
    const Eigen::Vector2d normal = Eigen::Vector2d(-d.y(), d.x()).normalized();
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector2d p = s.a_px + (k + 0.5) / n * d;
      ++total;
      if (p.x() < 1 || p.y() < 1 || p.x() > 640 - 2 || p.y() > 480 - 2) continue;
      const int x0 = static_cast<int>(std::floor(p.x())), y0 = static_cast<int>(std::floor(p.y()));
      const double fx = p.x() - x0, fy = p.y() - y0;
      auto at = [&](const cv::Mat& m) {
        return (1 - fx) * (1 - fy) * m.at<float>(y0, x0) + fx * (1 - fy) * m.at<float>(y0, x0 + 1) +
               (1 - fx) * fy * m.at<float>(y0 + 1, x0) + fx * fy * m.at<float>(y0 + 1, x0 + 1);
      };
      sum += std::abs(at(g.gx) * normal.x() + at(g.gy) * normal.y());
      ++inside;
    }
  }
  ASSERT_GT(inside, 20);
  ASSERT_LT(inside, total - 20);  // a good part of the contour is outside
  EXPECT_EQ(details.num_points, inside);
  EXPECT_EQ(details.points.size(), static_cast<std::size_t>(inside));
  for (const auto& p : details.points) EXPECT_TRUE(camera.in_image(p, 1.0));
  EXPECT_NEAR(details.energy, sum / inside, 1e-9);
  EXPECT_NEAR(energy.evaluate(pose, camera, g), sum / inside, 1e-9);

  // Entirely outside: no point, energy 0.
  Pose away = pose;
  away.translation().x() = -1.0;
  const EnergyDetails none = energy.evaluate_details(away, camera, g);
  EXPECT_EQ(none.num_points, 0);
  EXPECT_EQ(none.energy, 0.0);
  EXPECT_GT(none.segments.size(), 0u);
}

TEST(ContourEnergy, RejectsBadInput) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.1, 0.1, 0.1, false));
  EXPECT_THROW(ContourEnergy(mesh, nullptr, 45.0, 0.0), std::invalid_argument);
  EXPECT_THROW(ContourEnergy(std::shared_ptr<const ContourExtractor>(), 2.0),
               std::invalid_argument);
  const ContourEnergy energy(mesh, nullptr, 45.0, 2.0);
  EXPECT_THROW(energy.evaluate(test::make_pose(0.5), test::make_camera(), GradientImage{}),
               std::invalid_argument);
}

}  // namespace
}  // namespace kct
