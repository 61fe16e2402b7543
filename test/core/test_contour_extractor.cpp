#include <gtest/gtest.h>

#include <cmath>

#include "klt_contour_tracker/core/contour_extractor.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

/// Appends triangles, each turned so that its normal points away from `inside` (convex parts).
void add_outward(Mesh& mesh, int a, int b, int c, const Eigen::Vector3d& inside) {
  const auto &pa = mesh.vertices[a], &pb = mesh.vertices[b], &pc = mesh.vertices[c];
  if ((pb - pa).cross(pc - pa).dot((pa + pb + pc) / 3.0 - inside) < 0.0) std::swap(b, c);
  mesh.faces.emplace_back(a, b, c);
}

using test::append_box;

std::shared_ptr<const Mesh> make_cube(double half_size_m) {
  auto mesh = std::make_shared<Mesh>();
  append_box(*mesh, Eigen::Vector3d::Constant(-half_size_m), Eigen::Vector3d::Constant(half_size_m));
  return mesh;
}

/// Closed cylinder around the z axis: `sides` side quads (rim vertex i at angle 2 pi i / sides),
/// caps as fans around a centre vertex. 4 * sides faces, 6 * sides shared edges.
std::shared_ptr<const Mesh> make_cylinder(int sides, double radius_m, double height_m) {
  auto mesh = std::make_shared<Mesh>();
  for (double z : {0.5 * height_m, -0.5 * height_m})
    for (int i = 0; i < sides; ++i) {
      const double angle = 2.0 * M_PI * i / sides;
      mesh->vertices.emplace_back(radius_m * std::cos(angle), radius_m * std::sin(angle), z);
    }
  mesh->vertices.emplace_back(0, 0, 0.5 * height_m);   // 2 * sides: top centre
  mesh->vertices.emplace_back(0, 0, -0.5 * height_m);  // 2 * sides + 1: bottom centre
  const Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (int i = 0; i < sides; ++i) {
    const int j = (i + 1) % sides;
    add_outward(*mesh, i, j, sides + j, origin);
    add_outward(*mesh, i, sides + j, sides + i, origin);
    add_outward(*mesh, 2 * sides, i, j, origin);
    add_outward(*mesh, 2 * sides + 1, sides + i, sides + j, origin);
  }
  return mesh;
}

/// Camera at `eye` (object frame) looking at `target`; image y points away from +z when
/// possible.
Pose look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target = Eigen::Vector3d::Zero()) {
  const Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  if (std::abs(z.dot(up)) > 0.99) up = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d x = (-up).cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d r;
  r.row(0) = x.transpose();
  r.row(1) = y.transpose();
  r.row(2) = z.transpose();
  Pose pose = Pose::Identity();
  pose.linear() = r;
  pose.translation() = -r * eye;
  return pose;
}

struct Counts {
  int contour = 0, sharp = 0;
};

Counts count(const ContourExtractor& extractor, const Pose& pose) {
  std::vector<EdgeType> types;
  extractor.classify(pose, types);
  EXPECT_EQ(types.size(), extractor.edges().size());
  Counts c;
  for (EdgeType t : types) {
    c.contour += t == EdgeType::kContour;
    c.sharp += t == EdgeType::kSharp;
  }
  return c;
}

const PinholeCamera kCamera(500.0, 500.0, 319.5, 239.5, 640, 480);

class CubeTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    cube_ = make_cube(0.05);
    table_ = VisibilityTable::build(*cube_, 4, 128, "");
  }
  static void TearDownTestSuite() {
    cube_.reset();
    table_.reset();
  }
  static std::shared_ptr<const Mesh> cube_;
  static std::shared_ptr<const VisibilityTable> table_;
};
std::shared_ptr<const Mesh> CubeTest::cube_;
std::shared_ptr<const VisibilityTable> CubeTest::table_;

TEST_F(CubeTest, EdgeCount) {
  const ContourExtractor extractor(cube_, table_, 45.0);
  EXPECT_EQ(extractor.edges().size(), 18u);  // 12 cube edges + 6 coplanar quad diagonals
}

TEST_F(CubeTest, FaceOn) {
  const ContourExtractor extractor(cube_, table_, 45.0);
  // Only the top quad faces the camera: its 4 border edges are contour, its diagonal is
  // between two coplanar front faces (neither contour nor sharp).
  const Counts c = count(extractor, look_at(Eigen::Vector3d(0, 0, 0.5)));
  EXPECT_EQ(c.contour, 4);
  EXPECT_EQ(c.sharp, 0);
}

TEST_F(CubeTest, CornerView) {
  const ContourExtractor extractor(cube_, table_, 45.0);
  // Three front quads: a hexagonal outline (6 contour edges) and the 3 edges meeting at the
  // corner (sharp); the 3 diagonals are coplanar.
  const Counts c = count(extractor, look_at(0.5 * Eigen::Vector3d(1, 1, 1).normalized()));
  EXPECT_EQ(c.contour, 6);
  EXPECT_EQ(c.sharp, 3);
  // The projected segments are exactly those 9 edges and lie in the image.
  const std::vector<ContourSegment> segments =
      extractor.extract(look_at(0.5 * Eigen::Vector3d(1, 1, 1).normalized()), kCamera);
  EXPECT_EQ(segments.size(), 9u);
  for (const auto& s : segments) {
    EXPECT_TRUE(kCamera.in_image(s.a_px));
    EXPECT_TRUE(kCamera.in_image(s.b_px));
    EXPECT_GT((s.b_px - s.a_px).norm(), 10.0);
  }
}

TEST_F(CubeTest, EdgeView) {
  const ContourExtractor extractor(cube_, table_, 45.0);
  // +x and +z quads face the camera: 1 sharp edge between them, 3 + 3 contour edges.
  const Counts c = count(extractor, look_at(0.5 * Eigen::Vector3d(1, 0, 1).normalized()));
  EXPECT_EQ(c.contour, 6);
  EXPECT_EQ(c.sharp, 1);
}

TEST_F(CubeTest, AngleThresholdAndNoTable) {
  // Without a table nothing is treated as self-occluded (convex cube: same result); with
  // alpha = 100 deg the 90 deg cube edges are no longer sharp.
  const ContourExtractor no_table(cube_, nullptr, 45.0);
  const Counts c = count(no_table, look_at(0.5 * Eigen::Vector3d(1, 1, 1).normalized()));
  EXPECT_EQ(c.contour, 6);
  EXPECT_EQ(c.sharp, 3);
  const ContourExtractor wide(cube_, table_, 100.0);
  const Counts w = count(wide, look_at(0.5 * Eigen::Vector3d(1, 1, 1).normalized()));
  EXPECT_EQ(w.contour, 6);
  EXPECT_EQ(w.sharp, 0);
}

TEST_F(CubeTest, SegmentsMatchProjectedCorners) {
  const ContourExtractor extractor(cube_, table_, 45.0);
  const Pose pose = look_at(Eigen::Vector3d(0, 0, 0.5));
  const std::vector<ContourSegment> segments = extractor.extract(pose, kCamera);
  ASSERT_EQ(segments.size(), 4u);
  // The top square (z = 0.05) at depth 0.45: half side 0.05 * 500 / 0.45 px around the centre.
  const double half_px = 0.05 * 500.0 / 0.45;
  for (const auto& s : segments) {
    EXPECT_EQ(s.type, EdgeType::kContour);
    for (const Eigen::Vector2d& p : {s.a_px, s.b_px}) {
      EXPECT_NEAR(std::abs(p.x() - 319.5), half_px, 1e-9);
      EXPECT_NEAR(std::abs(p.y() - 239.5), half_px, 1e-9);
    }
    EXPECT_NEAR((s.b_px - s.a_px).norm(), 2.0 * half_px, 1e-9);
  }
}

TEST_F(CubeTest, BehindCameraSkipped) {
  const ContourExtractor extractor(cube_, table_, 45.0);
  // Camera above the cube at x = 0.02 looking along +x: only the top quad faces it (4 contour
  // edges), but its corners at x = -0.05 are behind the camera, so only the edge at x = 0.05
  // (depth 0.03 m) is projected.
  const Pose pose = look_at(Eigen::Vector3d(0.02, 0, 0.2), Eigen::Vector3d(1.02, 0, 0.2));
  const Counts c = count(extractor, pose);
  EXPECT_EQ(c.contour, 4);
  EXPECT_EQ(c.sharp, 0);
  std::vector<ContourSegment> segments;
  extractor.extract(pose, kCamera, segments);
  ASSERT_EQ(segments.size(), 1u);
  const MeshEdge& edge = extractor.edges()[segments[0].edge];
  EXPECT_DOUBLE_EQ(cube_->vertices[edge.v0].x(), 0.05);
  EXPECT_DOUBLE_EQ(cube_->vertices[edge.v1].x(), 0.05);
  EXPECT_TRUE(segments[0].a_px.allFinite());
  EXPECT_TRUE(segments[0].b_px.allFinite());
}

TEST(ContourExtractor, CylinderSideView) {
  const auto cylinder = make_cylinder(16, 0.05, 0.1);
  const auto table = VisibilityTable::build(*cylinder, 4, 128, "");
  const ContourExtractor extractor(cylinder, table, 45.0);
  EXPECT_EQ(extractor.edges().size(), 96u);
  // Camera at (0.5, 0, 0): both caps are back-facing; the 8 side quads with centre angle
  // |phi| <= 78.75 deg face the camera (n . c > n . v needs cos(phi) > 0.098). Contour: the
  // 2 silhouette side edges at +-90 deg, and the 8 top and 8 bottom rim edges of the front
  // quads. Side edges between front quads are 22.5 deg apart: not sharp.
  const Counts c = count(extractor, look_at(Eigen::Vector3d(0.5, 0, 0)));
  EXPECT_EQ(c.contour, 18);
  EXPECT_EQ(c.sharp, 0);
}

TEST(ContourExtractor, CylinderElevatedView) {
  const auto cylinder = make_cylinder(16, 0.05, 0.1);
  const auto table = VisibilityTable::build(*cylinder, 4, 128, "");
  const ContourExtractor extractor(cylinder, table, 45.0);
  // Camera 30 deg above the side, at 0.5 m: the top cap faces it, the bottom does not; the
  // same 8 side quads face it (cos(phi) > 0.113). Top rim: 8 sharp edges (cap meets front
  // quad at 90 deg) and 8 contour edges (cap meets back quad); bottom rim: 8 contour edges
  // under the front quads; plus the 2 silhouette side edges.
  const double e = 30.0 * M_PI / 180.0;
  const Counts c =
      count(extractor, look_at(0.5 * Eigen::Vector3d(std::cos(e), 0, std::sin(e))));
  EXPECT_EQ(c.contour, 18);
  EXPECT_EQ(c.sharp, 8);
}

TEST(ContourExtractor, HexagonalPrismSharpSideEdge) {
  const auto prism = make_cylinder(6, 0.05, 0.1);
  const auto table = VisibilityTable::build(*prism, 4, 128, "");
  const ContourExtractor extractor(prism, table, 45.0);
  // Camera at (0.5, 0, 0): quads centred at +-30 deg face it; the side edge at 0 deg joins
  // them at 60 deg > alpha (sharp); the side edges at +-60 deg are silhouettes; 2 + 2 rim
  // edges of the front quads are contour.
  const Counts c = count(extractor, look_at(Eigen::Vector3d(0.5, 0, 0)));
  EXPECT_EQ(c.contour, 6);
  EXPECT_EQ(c.sharp, 1);
  const ContourExtractor blunt(prism, table, 65.0);
  EXPECT_EQ(count(blunt, look_at(Eigen::Vector3d(0.5, 0, 0))).sharp, 0);
}

TEST(ContourExtractor, SelfOcclusionRemovesHiddenEdges) {
  // A small box below a large flat one, seen from above: without the visibility table the
  // small box's front faces (its top and, seen from this side, its +x face) add 6 contour
  // edges and 1 sharp edge; the table removes them.
  auto mesh = std::make_shared<Mesh>();
  append_box(*mesh, Eigen::Vector3d(-0.1, -0.1, 0.02), Eigen::Vector3d(0.1, 0.1, 0.06));
  append_box(*mesh, Eigen::Vector3d(-0.05, -0.05, -0.06), Eigen::Vector3d(0.05, 0.05, -0.02));
  const auto table = VisibilityTable::build(*mesh, 4, 256, "");
  // ~7 deg off the z axis (see test_visibility_table: the exactly axis-aligned viewpoint is
  // avoided).
  const Pose pose = look_at(0.6 * Eigen::Vector3d(0.1, 0.06, 1.0).normalized());

  const Counts without = count(ContourExtractor(mesh, nullptr, 45.0), pose);
  EXPECT_EQ(without.contour, 10);
  EXPECT_EQ(without.sharp, 1);
  const Counts with = count(ContourExtractor(mesh, table, 45.0), pose);
  EXPECT_EQ(with.contour, 4);
  EXPECT_EQ(with.sharp, 0);
}

TEST(ContourExtractor, CachedSetFollowsTheViewpoint) {
  // Consecutive calls from different sides must not reuse a stale invisible-face set.
  auto mesh = std::make_shared<Mesh>();
  append_box(*mesh, Eigen::Vector3d(-0.1, -0.1, 0.02), Eigen::Vector3d(0.1, 0.1, 0.06));
  append_box(*mesh, Eigen::Vector3d(-0.05, -0.05, -0.06), Eigen::Vector3d(0.05, 0.05, -0.02));
  const auto table = VisibilityTable::build(*mesh, 3, 128, "");
  const ContourExtractor extractor(mesh, table, 45.0);
  const Pose above = look_at(0.6 * Eigen::Vector3d(0.1, 0.06, 1.0).normalized());
  const Pose below = look_at(0.6 * Eigen::Vector3d(0.1, 0.06, -1.0).normalized());
  // From above the downward faces are in S, from below they are the visible ones: a stale
  // set would drop contour edges. Each result must equal that of a fresh extractor.
  for (const Pose* pose : {&above, &below, &above, &below}) {
    const Counts reused = count(extractor, *pose);
    const Counts fresh = count(ContourExtractor(mesh, table, 45.0), *pose);
    EXPECT_EQ(reused.contour, fresh.contour);
    EXPECT_EQ(reused.sharp, fresh.sharp);
    EXPECT_GE(reused.contour, 4);
  }
}

TEST(ContourExtractor, ExtractEqualsAFullClassificationAlongAPath) {
  // extract() classifies only the candidate edges selected for a nearby camera centre; along
  // a path of small and large moves (candidates reused, then re-selected) its segments must be
  // exactly those of classify() on every edge.
  const auto cylinder = make_cylinder(64, 0.05, 0.1);  // many near-grazing side faces
  const auto table = VisibilityTable::build(*cylinder, 3, 128, "");
  const ContourExtractor extractor(cylinder, table, 45.0);
  const PinholeCamera camera(600, 600, 320, 240, 640, 480);
  std::vector<EdgeType> types;
  std::vector<ContourSegment> segments;
  for (int step = 0; step < 120; ++step) {
    // 1 deg steps around the object with a 40 deg jump every 30 steps.
    const double azimuth = (step + 40 * (step / 30)) * M_PI / 180.0;
    const Pose pose = look_at(0.5 * Eigen::Vector3d(std::cos(azimuth), std::sin(azimuth),
                                                    0.3 + 0.2 * std::sin(3 * azimuth))
                                        .normalized());
    extractor.extract(pose, camera, segments);
    extractor.classify(pose, types);
    std::vector<int> expected;
    for (std::size_t i = 0; i < types.size(); ++i)
      if (types[i] != EdgeType::kOther) expected.push_back(static_cast<int>(i));
    ASSERT_EQ(segments.size(), expected.size()) << "step " << step;
    for (std::size_t k = 0; k < segments.size(); ++k) {
      EXPECT_EQ(segments[k].edge, expected[k]) << "step " << step;
      EXPECT_EQ(segments[k].type, types[expected[k]]) << "step " << step;
    }
  }
}

TEST(ContourExtractor, RejectsBadInput) {
  const auto cube = make_cube(0.05);
  EXPECT_THROW(ContourExtractor(nullptr, nullptr, 45.0), std::invalid_argument);
  EXPECT_THROW(ContourExtractor(cube, nullptr, -1.0), std::invalid_argument);
  const auto other = VisibilityTable::build(*make_cylinder(8, 0.05, 0.1), 1, 64, "");
  EXPECT_THROW(ContourExtractor(cube, other, 45.0), std::invalid_argument);
}


// --- Open and non-manifold meshes (CAD exports: floors, walls, fins) ---

/// The cube of half size 0.05 m without its +z quad: an open box, its 4 rim edges belong to one
/// face each.
std::shared_ptr<const Mesh> make_open_box() {
  auto mesh = std::make_shared<Mesh>();
  append_box(*mesh, Eigen::Vector3d::Constant(-0.05), Eigen::Vector3d::Constant(0.05));
  mesh->faces.erase(mesh->faces.begin() + 2, mesh->faces.begin() + 4);  // the +z quad
  return mesh;
}

/// Indices (into edges()) of the edges classified `type` for the pose.
std::vector<int> edges_of_type(const ContourExtractor& extractor, const Pose& pose, EdgeType type) {
  std::vector<EdgeType> types;
  extractor.classify(pose, types);
  std::vector<int> result;
  for (std::size_t i = 0; i < types.size(); ++i)
    if (types[i] == type) result.push_back(static_cast<int>(i));
  return result;
}

TEST(ContourExtractor, OpenBoxRimIsContour) {
  const auto box = make_open_box();
  const auto table = VisibilityTable::build(*box, 4, 128, "");
  const ContourExtractor extractor(box, table, 45.0);
  // 13 two-face edges (12 cube edges minus the 4 rim ones, plus 5 diagonals) and 4 boundary.
  ASSERT_EQ(extractor.edges().size(), 17u);
  int boundary = 0;
  for (const MeshEdge& e : extractor.edges()) boundary += e.face1 < 0;
  EXPECT_EQ(boundary, 4);
  // Seen from +x, 45 deg above: only the +x wall faces the camera. All 4 of its sides are the
  // outline: bottom and sides against back-facing walls, and the rim edge at z = 0.05 (a
  // boundary edge, which Algorithm 1 alone would drop: only 3 edges).
  const Pose pose = look_at(0.5 * Eigen::Vector3d(1, 0, 1).normalized());
  const std::vector<int> contour = edges_of_type(extractor, pose, EdgeType::kContour);
  EXPECT_EQ(contour.size(), 4u);
  EXPECT_TRUE(edges_of_type(extractor, pose, EdgeType::kSharp).empty());
  int rim = 0;
  for (int i : contour) {
    const MeshEdge& e = extractor.edges()[i];
    EXPECT_DOUBLE_EQ(box->vertices[e.v0].x(), 0.05);
    EXPECT_DOUBLE_EQ(box->vertices[e.v1].x(), 0.05);
    rim += e.face1 < 0;
  }
  EXPECT_EQ(rim, 1);
  // Projected: 4 segments forming the wall's outline in the image.
  const std::vector<ContourSegment> segments = extractor.extract(pose, kCamera);
  EXPECT_EQ(segments.size(), 4u);
  for (const auto& s : segments) EXPECT_EQ(s.type, EdgeType::kContour);
}

TEST(ContourExtractor, OpenBoxFromBelow) {
  // From below, slightly off axis (camera at x, y inside the box's footprint): the bottom quad
  // is the only front face; its 4 sides are contour (the walls are back-facing), the rim edges
  // belong to back-facing walls and are not drawn.
  const auto box = make_open_box();
  const ContourExtractor extractor(box, VisibilityTable::build(*box, 4, 128, ""), 45.0);
  const Pose pose = look_at(0.6 * Eigen::Vector3d(0.05, 0.03, -1.0).normalized());
  const std::vector<int> contour = edges_of_type(extractor, pose, EdgeType::kContour);
  EXPECT_EQ(contour.size(), 4u);
  for (int i : contour) {
    const MeshEdge& e = extractor.edges()[i];
    EXPECT_DOUBLE_EQ(box->vertices[e.v0].z(), -0.05);
    EXPECT_DOUBLE_EQ(box->vertices[e.v1].z(), -0.05);
  }
}

TEST(ContourExtractor, SinglePolygonOutlinedFromItsFront) {
  // A hexagon in the z = 0 plane, normal +z, as a fan of 4 triangles: 6 boundary edges and
  // 3 inner diagonals.
  auto hexagon = std::make_shared<Mesh>();
  for (int i = 0; i < 6; ++i)
    hexagon->vertices.emplace_back(0.05 * std::cos(M_PI * i / 3), 0.05 * std::sin(M_PI * i / 3), 0);
  for (int i = 1; i < 5; ++i) hexagon->faces.emplace_back(0, i, i + 1);
  const auto table = VisibilityTable::build(*hexagon, 4, 128, "");
  const ContourExtractor extractor(hexagon, table, 45.0);
  ASSERT_EQ(extractor.edges().size(), 9u);
  const Pose front = look_at(0.5 * Eigen::Vector3d(0.2, 0.1, 1.0).normalized());
  EXPECT_EQ(count(extractor, front).contour, 6);
  EXPECT_EQ(count(extractor, front).sharp, 0);
  // The outline's projection: each boundary edge's segment, about the hexagon's side length
  // (0.05 m at ~0.5 m: ~50 px).
  for (const auto& s : extractor.extract(front, kCamera)) {
    EXPECT_TRUE(kCamera.in_image(s.a_px));
    EXPECT_NEAR((s.b_px - s.a_px).norm(), 50.0, 10.0);
  }
  // From behind the polygon is back-facing: nothing is drawn.
  const Pose back = look_at(0.5 * Eigen::Vector3d(0.2, 0.1, -1.0).normalized());
  EXPECT_EQ(count(extractor, back).contour, 0);
  EXPECT_EQ(count(extractor, back).sharp, 0);
  // Without a table: the same.
  EXPECT_EQ(count(ContourExtractor(hexagon, nullptr, 45.0), front).contour, 6);
}

TEST(ContourExtractor, NonManifoldEdge) {
  // A plate of two quads (z = 0, normal +z) with a fin (x = 0, normal +x) standing on the
  // line x = 0 they share: that line is an edge of 3 faces.
  auto mesh = std::make_shared<Mesh>();
  mesh->vertices = {{0, -0.05, 0},     {0, 0.05, 0},      {-0.05, -0.05, 0}, {-0.05, 0.05, 0},
                    {0.05, -0.05, 0},  {0.05, 0.05, 0},   {0, -0.05, 0.05},  {0, 0.05, 0.05}};
  mesh->faces = {{2, 0, 1}, {2, 1, 3},   // plate x < 0
                 {0, 4, 5}, {0, 5, 1},   // plate x > 0
                 {0, 1, 7}, {0, 7, 6}};  // fin, normal +x
  for (int f = 0; f < 6; ++f) ASSERT_GT(mesh->face_normal(f).sum(), 0.99) << f;
  const ContourExtractor extractor(mesh, nullptr, 45.0);
  // Every edge once (13: 6 plate sides, 2 plate diagonals, 3 fin sides, the fin's diagonal and
  // the spine), the spine among the edges after the two-face ones.
  ASSERT_EQ(extractor.edges().size(), 13u);
  int spine = -1;
  for (std::size_t i = 0; i < extractor.edges().size(); ++i) {
    const MeshEdge& e = extractor.edges()[i];
    if (std::min(e.v0, e.v1) == 0 && std::max(e.v0, e.v1) == 1) {
      EXPECT_EQ(spine, -1) << "the spine is listed twice";
      spine = static_cast<int>(i);
    }
  }
  ASSERT_GE(spine, 3);
  // From +x above: plate and fin face the camera, 90 deg apart: the spine is sharp.
  std::vector<EdgeType> types;
  extractor.classify(look_at(0.5 * Eigen::Vector3d(1, 0.1, 1).normalized()), types);
  EXPECT_EQ(types[spine], EdgeType::kSharp);
  // From -x above: the fin is back-facing, the plate is not: the spine is on the outline.
  extractor.classify(look_at(0.5 * Eigen::Vector3d(-1, 0.1, 1).normalized()), types);
  EXPECT_EQ(types[spine], EdgeType::kContour);
  // From below: nothing faces the camera.
  extractor.classify(look_at(0.5 * Eigen::Vector3d(-1, 0.1, -1).normalized()), types);
  for (EdgeType t : types) EXPECT_EQ(t, EdgeType::kOther);
  // The rest of the plate's outline is found as boundary edges (from +x above: 6 plate sides,
  // the fin's top and the fin's two vertical sides).
  const Counts c = count(extractor, look_at(0.5 * Eigen::Vector3d(1, 0.1, 1).normalized()));
  EXPECT_EQ(c.contour, 9);
  EXPECT_EQ(c.sharp, 1);
}

}  // namespace
}  // namespace kct
