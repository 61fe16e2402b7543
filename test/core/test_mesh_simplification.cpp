#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "klt_contour_tracker/core/mesh_simplification.h"
#include "klt_contour_tracker/core/object_search.h"
#include "klt_contour_tracker/core/renderer.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

/// A UV sphere of `radius_m` with `rings` x `segments` quads (split in two triangles, CCW from
/// outside; the poles are fans): a dense scan-like mesh.
Mesh make_sphere(double radius_m, int rings, int segments) {
  Mesh mesh;
  mesh.vertices.emplace_back(0, 0, radius_m);  // north pole
  for (int r = 1; r < rings; ++r) {
    const double theta = M_PI * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2.0 * M_PI * s / segments;
      mesh.vertices.emplace_back(radius_m * std::sin(theta) * std::cos(phi),
                                 radius_m * std::sin(theta) * std::sin(phi),
                                 radius_m * std::cos(theta));
    }
  }
  mesh.vertices.emplace_back(0, 0, -radius_m);  // south pole
  const int south = static_cast<int>(mesh.vertices.size()) - 1;
  const auto at = [&](int ring, int s) { return 1 + (ring - 1) * segments + (s % segments); };
  for (int s = 0; s < segments; ++s) mesh.faces.emplace_back(0, at(1, s), at(1, s + 1));
  for (int r = 1; r + 1 < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      mesh.faces.emplace_back(at(r, s), at(r + 1, s), at(r + 1, s + 1));
      mesh.faces.emplace_back(at(r, s), at(r + 1, s + 1), at(r, s + 1));
    }
  for (int s = 0; s < segments; ++s)
    mesh.faces.emplace_back(south, at(rings - 1, s + 1), at(rings - 1, s));
  return mesh;
}

/// A flat square of side `side_m` in the object's z = 0 plane, split into n x n quads (an open
/// mesh: its outline is boundary edges), facing +z.
Mesh make_grid(double side_m, int n) {
  Mesh mesh;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x)
      mesh.vertices.emplace_back(side_m * (x / double(n) - 0.5), side_m * (y / double(n) - 0.5), 0);
  const auto at = [&](int x, int y) { return y * (n + 1) + x; };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      mesh.faces.emplace_back(at(x, y), at(x + 1, y), at(x + 1, y + 1));
      mesh.faces.emplace_back(at(x, y), at(x + 1, y + 1), at(x, y + 1));
    }
  return mesh;
}

/// Pixels where the two silhouettes differ that are farther than `tolerance_px` from the
/// first one's outline.
int differences_off_the_outline(const cv::Mat& a, const cv::Mat& b, int tolerance_px) {
  const cv::Mat kernel = cv::getStructuringElement(
      cv::MORPH_RECT, cv::Size(2 * tolerance_px + 1, 2 * tolerance_px + 1));
  cv::Mat grown, shrunk, band, differ;
  cv::dilate(a, grown, kernel);
  cv::erode(a, shrunk, kernel);
  band = grown - shrunk;  // within tolerance_px of the outline
  cv::bitwise_xor(a, b, differ);
  differ.setTo(0, band);
  return cv::countNonZero(differ);
}

void expect_same_silhouette(const Mesh& original, const Mesh& simplified, double distance_m) {
  const auto full = std::make_shared<const Mesh>(original);
  const auto coarse = std::make_shared<const Mesh>(simplified);
  const PinholeCamera camera = test::make_camera();
  for (const Eigen::Vector3d& angles_deg :
       {Eigen::Vector3d(25, -35, 10), Eigen::Vector3d(-60, 20, 80), Eigen::Vector3d(5, 85, -30)}) {
    const Pose pose = test::make_pose(distance_m, angles_deg.x(), angles_deg.y(), angles_deg.z());
    const cv::Mat a = Renderer(full).render_silhouette(pose, camera);
    const cv::Mat b = Renderer(coarse).render_silhouette(pose, camera);
    ASSERT_GT(cv::countNonZero(a), 1000);
    EXPECT_EQ(differences_off_the_outline(a, b, 1), 0) << "angles " << angles_deg.transpose();
    // Along the outline they differ by a fraction of a pixel: few pixels flip.
    cv::Mat differ;
    cv::bitwise_xor(a, b, differ);
    EXPECT_LT(cv::countNonZero(differ), 0.02 * cv::countNonZero(a))
        << "angles " << angles_deg.transpose();
  }
}

TEST(MeshSimplification, ADenseSphereLosesMostFacesAndKeepsItsSilhouette) {
  const Mesh sphere = make_sphere(0.05, 96, 192);  // 36672 faces
  // 0.2 mm: 0.4 px at 0.3 m with fx = 600 px.
  const Mesh simplified = simplified_mesh(sphere, 0.0002);
  EXPECT_LT(simplified.faces.size(), sphere.faces.size() / 4);
  EXPECT_GT(simplified.faces.size(), 100u);
  // Every vertex it keeps is one of the sphere's (on it), and every vertex is used.
  for (const Eigen::Vector3d& v : simplified.vertices) EXPECT_NEAR(v.norm(), 0.05, 1e-6);
  std::vector<bool> used(simplified.vertices.size(), false);
  for (const Eigen::Vector3i& f : simplified.faces)
    for (int k = 0; k < 3; ++k) {
      ASSERT_GE(f[k], 0);
      ASSERT_LT(f[k], static_cast<int>(simplified.vertices.size()));
      used[f[k]] = true;
    }
  for (bool u : used) EXPECT_TRUE(u);
  // Faces still face outwards (CCW from outside).
  for (int f = 0; f < static_cast<int>(simplified.faces.size()); ++f) {
    const Eigen::Vector3i& face = simplified.faces[f];
    const Eigen::Vector3d centre = (simplified.vertices[face[0]] + simplified.vertices[face[1]] +
                                    simplified.vertices[face[2]]) /
                                   3;
    EXPECT_GT(simplified.face_normal(f).dot(centre), 0.0) << "face " << f;
  }
  expect_same_silhouette(sphere, simplified, 0.3);
}

TEST(MeshSimplification, FlatFacesCollapseAndTheOutlineStays) {
  // A box whose six faces are each a 24 x 24 grid of quads: coplanar triangles merge.
  Mesh box;
  const double side = 0.08;
  for (int axis = 0; axis < 3; ++axis)
    for (int sign : {-1, 1}) {
      const Mesh grid = make_grid(side, 24);
      Eigen::Matrix3d rotation;
      // Maps the grid's +z normal onto sign * axis, keeping the rotation proper.
      if (axis == 2)
        rotation = Eigen::AngleAxisd(sign > 0 ? 0.0 : M_PI, Eigen::Vector3d::UnitX());
      else if (axis == 0)
        rotation = Eigen::AngleAxisd(sign * M_PI / 2, Eigen::Vector3d::UnitY());
      else
        rotation = Eigen::AngleAxisd(-sign * M_PI / 2, Eigen::Vector3d::UnitX());
      Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
      transform.linear() = rotation;
      transform.translation() = rotation * Eigen::Vector3d(0, 0, side / 2);
      append_mesh(box, grid, transform);
    }
  ASSERT_EQ(box.faces.size(), 6u * 2 * 24 * 24);
  const Mesh simplified = simplified_mesh(box, 0.0001);
  EXPECT_LT(simplified.faces.size(), box.faces.size() / 10);
  expect_same_silhouette(box, simplified, 0.4);
}

TEST(MeshSimplification, AnOpenMeshKeepsItsBoundaryOutline) {
  const Mesh grid = make_grid(0.1, 40);  // one open polygon: its outline is boundary edges
  const Mesh simplified = simplified_mesh(grid, 0.0002);
  EXPECT_LT(simplified.faces.size(), grid.faces.size() / 10);
  EXPECT_GE(simplified.faces.size(), 2u);
  const auto full = std::make_shared<const Mesh>(grid);
  const auto coarse = std::make_shared<const Mesh>(simplified);
  const PinholeCamera camera = test::make_camera();
  const Pose pose = test::make_pose(0.35, 20, 0, 15);  // the +z side faces the camera
  const cv::Mat a = Renderer(full).render_silhouette(pose, camera);
  const cv::Mat b = Renderer(coarse).render_silhouette(pose, camera);
  ASSERT_GT(cv::countNonZero(a), 1000);
  EXPECT_EQ(differences_off_the_outline(a, b, 1), 0);
}

TEST(MeshSimplification, ZeroErrorCopiesTheGeometryWithoutTheTexture) {
  const Mesh box = test::make_box(0.08, 0.06, 0.05, /*textured=*/true);
  ASSERT_TRUE(box.has_texture());
  const Mesh copy = simplified_mesh(box, 0.0);
  EXPECT_EQ(copy.faces, box.faces);
  EXPECT_EQ(copy.vertices, box.vertices);
  EXPECT_FALSE(copy.has_texture());
  EXPECT_TRUE(copy.corner_uvs.empty());
  EXPECT_EQ(copy.base_color, box.base_color);
  // A mesh with nothing to collapse keeps its faces: a box's 12 triangles within 1 mm.
  EXPECT_EQ(simplified_mesh(box, 0.001).faces.size(), box.faces.size());
}

TEST(MeshSimplification, BadInputIsRefused) {
  const Mesh box = test::make_box(0.08, 0.06, 0.05, false);
  EXPECT_THROW(simplified_mesh(box, -0.001), std::invalid_argument);
  EXPECT_THROW(simplified_mesh(box, std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);
  EXPECT_THROW(simplified_mesh(box, std::numeric_limits<double>::infinity()),
               std::invalid_argument);
  Mesh broken = box;
  broken.faces.front() = Eigen::Vector3i(0, 1, static_cast<int>(box.vertices.size()));
  EXPECT_THROW(simplified_mesh(broken, 0.001), std::invalid_argument);
  broken.faces.front() = Eigen::Vector3i(0, -1, 2);
  EXPECT_THROW(simplified_mesh(broken, 0.001), std::invalid_argument);
  EXPECT_TRUE(simplified_mesh(Mesh{}, 0.001).faces.empty());
}

/// The colour search scores the dense sphere the same with its simplified silhouettes.
TEST(MeshSimplification, TheColourSearchScoresTheSameOnTheSimplifiedMesh) {
  auto sphere = std::make_shared<Mesh>(make_sphere(0.05, 96, 192));
  sphere->base_color = cv::Vec3b(40, 60, 200);
  const std::shared_ptr<const Mesh> mesh = sphere;
  const PinholeCamera camera = test::make_camera();
  const cv::Mat background(camera.size(), CV_8UC3, cv::Scalar(200, 120, 40));
  const Pose truth = test::make_pose(0.35);
  const cv::Mat frame = test::render_frame(Renderer(mesh), camera, truth, background, 3.0);
  ObjectSearchSettings simplified_settings;
  simplified_settings.silhouette_error_diameters = 0.001;  // 0.1 mm: 0.17 px at 0.35 m
  ObjectSearch full(mesh), simplified(mesh, simplified_settings);
  ASSERT_TRUE(full.learn(frame, truth, camera));
  ASSERT_TRUE(simplified.learn(frame, truth, camera));
  for (const Eigen::Vector3d& shift :
       {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.02, 0, 0), Eigen::Vector3d(0, -0.04, 0.03),
        Eigen::Vector3d(0.15, 0, 0)}) {
    const Pose pose = test::move(truth, 0, Eigen::Vector3d::UnitZ(), shift);
    EXPECT_NEAR(full.score(frame, pose, camera).contrast,
                simplified.score(frame, pose, camera).contrast, 0.005)
        << "shift " << shift.transpose();
  }
  // The search finds the sphere where the full mesh's search does.
  const std::vector<SearchCandidate> a =
      full.search(frame, test::move(truth, 0, Eigen::Vector3d::UnitZ(), {0.03, 0.02, 0}), camera);
  const std::vector<SearchCandidate> b = simplified.search(
      frame, test::move(truth, 0, Eigen::Vector3d::UnitZ(), {0.03, 0.02, 0}), camera);
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(b.empty());
  EXPECT_LT(
      (a.front().object_to_camera.translation() - b.front().object_to_camera.translation()).norm(),
      0.005);
  EXPECT_LT((b.front().object_to_camera.translation() - truth.translation()).norm(), 0.02);

  ObjectSearchSettings bad;
  bad.silhouette_error_diameters = 0.1;
  EXPECT_THROW(ObjectSearch(mesh, bad), std::invalid_argument);
  bad.silhouette_error_diameters = -0.001;
  EXPECT_THROW(ObjectSearch(mesh, bad), std::invalid_argument);
}

}  // namespace
}  // namespace kct
