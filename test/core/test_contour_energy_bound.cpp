// The bound on the work of one energy evaluation (issue 8, finding 3): however long the
// projected contour (many edges, an absurd focal length), at most ContourEnergy::kMaxSamples
// points plus one per segment are sampled.
#include <gtest/gtest.h>

#include "klt_contour_tracker/core/contour_energy.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

/// 10 x 10 cubes of 1 cm, 1.2 cm apart, in the object's x-y plane, centred at the origin.
std::shared_ptr<const Mesh> cube_grid() {
  auto mesh = std::make_shared<Mesh>();
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) {
      const Eigen::Vector3d lo(-0.06 + 0.012 * i, -0.06 + 0.012 * j, -0.005);
      test::append_box(*mesh, lo, lo + Eigen::Vector3d(0.01, 0.01, 0.01));
    }
  return mesh;
}

/// A gradient of 1 intensity unit per pixel along x everywhere.
GradientImage unit_gradient(int width, int height) {
  GradientImage g;
  g.gx = cv::Mat(height, width, CV_32F, cv::Scalar(1.0f));
  g.gy = cv::Mat(height, width, CV_32F, cv::Scalar(0.0f));
  return g;
}

TEST(ContourEnergyBound, LongContoursAreSampledAtMostKMaxSamplesTimes) {
  const ContourEnergy energy(cube_grid(), nullptr, 45.0, 2.0);
  Pose pose = Pose::Identity();
  pose.translation() = Eigen::Vector3d(0, 0, 0.4);
  // 6000 px focal length: each cube's front face is 150 px wide, the grid 1800 px, and its
  // sharp edges are ~60,000 px long (30,000 points at 2 px) inside the 2000x2000 image.
  const PinholeCamera camera(6000, 6000, 1000, 1000, 2000, 2000);
  const EnergyDetails details = energy.evaluate_details(pose, camera, unit_gradient(2000, 2000));
  double length = 0.0;
  for (const ContourSegment& s : details.segments) length += (s.b_px - s.a_px).norm();
  ASSERT_GT(length / 2.0, 1.2 * ContourEnergy::kMaxSamples);  // the bound is reached
  EXPECT_LE(details.num_points,
            ContourEnergy::kMaxSamples + static_cast<int>(details.segments.size()));
  EXPECT_GT(details.num_points, ContourEnergy::kMaxSamples / 2);  // still spread over all of it
  // Capped = the same contour sampled at the coarser spacing length / kMaxSamples.
  const ContourEnergy coarse(cube_grid(), nullptr, 45.0, length / ContourEnergy::kMaxSamples);
  EXPECT_NEAR(details.energy, coarse.evaluate(pose, camera, unit_gradient(2000, 2000)), 1e-3);
}

TEST(ContourEnergyBound, AbsurdFocalLengthsStayBounded) {
  // fx = 1e9 px: the contour is ~1e9 px long. Unbounded, this evaluation visited every 2 px of
  // it (19 s for fx = 1e7 in the issue); bounded, it samples at most kMaxSamples points.
  const ContourEnergy energy(cube_grid(), nullptr, 45.0, 2.0);
  Pose pose = Pose::Identity();
  pose.translation() = Eigen::Vector3d(0, 0, 0.4);
  const PinholeCamera camera(1e9, 1e9, 32, 32, 64, 64);
  const EnergyDetails details = energy.evaluate_details(pose, camera, unit_gradient(64, 64));
  EXPECT_LE(details.num_points,
            ContourEnergy::kMaxSamples + static_cast<int>(details.segments.size()));
}

}  // namespace
}  // namespace kct
