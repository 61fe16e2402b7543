#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "klt_contour_tracker/core/cao_reader.h"
#include "klt_contour_tracker/core/contour_extractor.h"
#include "klt_contour_tracker/core/mesh.h"

// ViSP .cao models written for these tests (test/core/data/cao): a cube, an open castle-like
// model (concave floor polygon, four walls, load() includes, a face from lines) and a cylinder
// with a circle.

namespace kct {
namespace {

const std::string kData = std::string(KCT_SOURCE_DIR) + "/test/core/data/cao/";

std::string read_text(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

/// A temporary .cao file with the given content; returns its path.
std::string temp_cao(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/kct_cao_" + name + ".cao";
  write_text(path, text);
  return path;
}

double area(const Mesh& mesh, int face) {
  const Eigen::Vector3i& f = mesh.faces[face];
  return 0.5 * (mesh.vertices[f[1]] - mesh.vertices[f[0]])
                   .cross(mesh.vertices[f[2]] - mesh.vertices[f[0]])
                   .norm();
}

Eigen::Vector3d centroid(const Mesh& mesh, int face) {
  const Eigen::Vector3i& f = mesh.faces[face];
  return (mesh.vertices[f[0]] + mesh.vertices[f[1]] + mesh.vertices[f[2]]) / 3.0;
}

TEST(CaoReader, Cube) {
  const CaoModel model = read_cao(kData + "cube.cao");
  ASSERT_EQ(model.points.size(), 8u);
  ASSERT_EQ(model.polygons.size(), 6u);
  EXPECT_EQ(model.polygons[0], (std::vector<int>{0, 3, 2, 1}));
  EXPECT_TRUE(model.points[6].isApprox(Eigen::Vector3d(0.1, 0.1, 0.1)));

  const Mesh mesh = load_mesh(kData + "cube.cao");
  EXPECT_EQ(mesh.vertices.size(), 8u);
  ASSERT_EQ(mesh.faces.size(), 12u);
  EXPECT_EQ(mesh.shared_edges().size(), 18u);                // closed
  EXPECT_NEAR(mesh.diameter(), 0.1 * std::sqrt(3.0), 1e-7);  // assimp keeps floats
  // Every triangle keeps the file's orientation: normal away from the cube's centre.
  const Eigen::Vector3d centre = Eigen::Vector3d::Constant(0.05);
  double total_area = 0.0;
  for (int f = 0; f < 12; ++f) {
    EXPECT_GT(mesh.face_normal(f).dot(centroid(mesh, f) - centre), 0.0) << "face " << f;
    total_area += area(mesh, f);
  }
  EXPECT_NEAR(total_area, 0.06, 1e-7);
  // scale applies as for any mesh file
  EXPECT_NEAR(load_mesh(kData + "cube.cao", 1000.0).diameter(), 100.0 * std::sqrt(3.0), 1e-4);
}

TEST(CaoReader, EarClippingCoversConcavePolygonsExactly) {
  // The castle floor (L-shaped hexagon) starting at each of its corners, and a comb with three
  // teeth: the triangles' areas sum to the polygon's (shoelace) area, all wound like it.
  const std::vector<Eigen::Vector3d> l_shape = {{0, 0, 0},     {0.2, 0, 0},   {0.2, 0.1, 0},
                                                {0.1, 0.1, 0}, {0.1, 0.2, 0}, {0, 0.2, 0}};
  // Three teeth 0.1 wide and 0.2 high on a 0.5 x 0.1 bar.
  const std::vector<Eigen::Vector3d> comb = {
      {0, 0, 0},     {0.5, 0, 0},   {0.5, 0.3, 0}, {0.4, 0.3, 0}, {0.4, 0.1, 0}, {0.3, 0.1, 0},
      {0.3, 0.3, 0}, {0.2, 0.3, 0}, {0.2, 0.1, 0}, {0.1, 0.1, 0}, {0.1, 0.3, 0}, {0, 0.3, 0}};
  for (const auto* shape : {&l_shape, &comb}) {
    const int n = static_cast<int>(shape->size());
    double shoelace = 0.0;
    for (int i = 0; i < n; ++i)
      shoelace += 0.5 * ((*shape)[i].x() * (*shape)[(i + 1) % n].y() -
                         (*shape)[(i + 1) % n].x() * (*shape)[i].y());
    ASSERT_GT(shoelace, 0.0);
    for (int start = 0; start < n; ++start) {
      std::vector<int> polygon;
      for (int i = 0; i < n; ++i) polygon.push_back((start + i) % n);
      const auto triangles = triangulate_polygon(*shape, polygon);
      EXPECT_EQ(static_cast<int>(triangles.size()), n - 2);
      double area = 0.0;
      for (const auto& t : triangles) {
        const double signed_area =
            0.5 * ((*shape)[t[1]] - (*shape)[t[0]]).cross((*shape)[t[2]] - (*shape)[t[0]]).z();
        EXPECT_GT(signed_area, 0.0) << "start " << start;
        area += signed_area;
      }
      EXPECT_NEAR(area, shoelace, 1e-12) << "start " << start;
    }
  }
}

TEST(CaoReader, OpenCastleWithIncludesAndFaceFromLines) {
  const CaoModel model = read_cao(kData + "castle.cao");
  ASSERT_EQ(model.points.size(), 14u);  // 6 floor + 8 tower, each file its own indices
  ASSERT_EQ(model.polygons.size(), 5u);
  // The face from lines (listed first in tower.cao) is the loop 1, 2, 6, 5 of the tower's
  // points, even though its second line is written 6 -> 2.
  EXPECT_EQ(model.polygons[1], (std::vector<int>{6 + 1, 6 + 2, 6 + 6, 6 + 5}));

  const Mesh mesh = load_mesh(kData + "castle.cao");
  // Floor: concave hexagon -> 4 triangles; 4 walls -> 8 triangles. Merged: the floor's and
  // the tower's points at (0,0,0) and (0.1,0.1,0) coincide.
  ASSERT_EQ(mesh.faces.size(), 12u);
  EXPECT_EQ(mesh.vertices.size(), 12u);
  double floor_area = 0.0, wall_area = 0.0;
  for (int f = 0; f < 12; ++f) {
    const Eigen::Vector3d n = mesh.face_normal(f);
    if (std::abs(n.z() - 1.0) < 1e-6) {
      floor_area += area(mesh, f);
      // The concave corner is respected: no triangle covers the notch [0.1, 0.2]^2.
      const Eigen::Vector3d c = centroid(mesh, f);
      EXPECT_FALSE(c.x() > 0.1 && c.y() > 0.1) << "triangle over the notch, face " << f;
    } else {
      EXPECT_NEAR(n.z(), 0.0, 1e-6);
      // Walls face away from the tower's axis.
      EXPECT_GT(n.dot(centroid(mesh, f) - Eigen::Vector3d(0.05, 0.05, 0.075)), 0.0) << f;
      wall_area += area(mesh, f);
    }
  }
  EXPECT_NEAR(floor_area, 0.2 * 0.2 - 0.1 * 0.1, 1e-7);
  EXPECT_NEAR(wall_area, 4 * 0.1 * 0.15, 1e-7);
}

TEST(CaoReader, OpenCastleOutlineFound) {
  // The castle seen from above in front of the +x and -y walls. Its outline is made of
  // boundary edges (floor sides, wall tops and bottoms), which Algorithm 1 alone ignores
  // (it would find only the 2 vertical edges beside the back walls).
  const auto mesh = std::make_shared<const Mesh>(load_mesh(kData + "castle.cao"));
  const ContourExtractor extractor(mesh, nullptr, 45.0);
  Eigen::Vector3d eye(0.6, -0.5, 0.6), target(0.1, 0.1, 0.05);
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  Eigen::Matrix3d r;
  r.row(0) = x.transpose();
  r.row(1) = z.cross(x).transpose();
  r.row(2) = z.transpose();
  Pose pose = Pose::Identity();
  pose.linear() = r;
  pose.translation() = -r * eye;
  std::vector<EdgeType> types;
  extractor.classify(pose, types);
  int contour = 0, sharp = 0, floor_sides = 0;
  for (std::size_t i = 0; i < types.size(); ++i) {
    contour += types[i] == EdgeType::kContour;
    sharp += types[i] == EdgeType::kSharp;
    const MeshEdge& e = extractor.edges()[i];
    floor_sides += types[i] == EdgeType::kContour && e.face1 < 0 &&
                   mesh->vertices[e.v0].z() == 0.0 && mesh->vertices[e.v1].z() == 0.0 &&
                   mesh->face_normal(e.face0).z() > 0.99;
  }
  // 6 floor sides, 2 tops and 2 bottoms of the front walls, 2 vertical edges next to the back
  // walls: 12 contour; the vertical edge between the two front walls is sharp.
  EXPECT_EQ(floor_sides, 6);
  EXPECT_EQ(contour, 12);
  EXPECT_EQ(sharp, 1);
}

TEST(CaoReader, WindowsLineEndingsReadTheSame) {
  // The castle's three files rewritten with CRLF line endings in a temporary folder.
  const std::string folder = ::testing::TempDir() + "/kct_cao_crlf";
  ASSERT_EQ(std::system(("mkdir -p '" + folder + "/castle_parts'").c_str()), 0);
  for (const std::string name :
       {"castle.cao", "castle_parts/floor.cao", "castle_parts/tower.cao"}) {
    std::string text = read_text(kData + name), crlf;
    for (char c : text) {
      if (c == '\n') crlf += '\r';
      crlf += c;
    }
    ASSERT_NE(crlf.find("\r\n"), std::string::npos);
    write_text(folder + "/" + name, crlf);
  }
  const CaoModel lf = read_cao(kData + "castle.cao");
  const CaoModel crlf = read_cao(folder + "/castle.cao");
  ASSERT_EQ(crlf.points.size(), lf.points.size());
  for (std::size_t i = 0; i < lf.points.size(); ++i) EXPECT_EQ(crlf.points[i], lf.points[i]);
  EXPECT_EQ(crlf.polygons, lf.polygons);
}

TEST(CaoReader, CylinderAndCircleTriangulated) {
  const CaoModel model = read_cao(kData + "cylinder.cao", 24);
  // 24 side quads and one 24-gon.
  ASSERT_EQ(model.polygons.size(), 25u);
  const Mesh mesh = load_mesh(kData + "cylinder.cao");  // 32 segments by default
  ASSERT_EQ(mesh.faces.size(), 2u * 32 + 30);  // tube quads + the 32-gon as a fan of triangles
  double side_area = 0.0, cap_area = 0.0;
  for (int f = 0; f < static_cast<int>(mesh.faces.size()); ++f) {
    const Eigen::Vector3d n = mesh.face_normal(f), c = centroid(mesh, f);
    if (std::abs(n.z() - 1.0) < 1e-6) {
      cap_area += area(mesh, f);
      EXPECT_NEAR(c.z(), 0.2, 1e-7);
    } else {
      // Side: outward (along the radial direction), vertical.
      EXPECT_NEAR(n.z(), 0.0, 1e-6);
      EXPECT_GT(n.dot(Eigen::Vector3d(c.x(), c.y(), 0.0).normalized()), 0.99) << f;
      side_area += area(mesh, f);
    }
  }
  // Inscribed 32-gon: side 2 pi r h * sin(pi/32)/(pi/32), cap 16 r^2 sin(2 pi / 32).
  const double k = std::sin(M_PI / 32) / (M_PI / 32);
  EXPECT_NEAR(side_area, 2 * M_PI * 0.05 * 0.2 * k, 1e-7);
  EXPECT_NEAR(cap_area, 16 * 0.05 * 0.05 * std::sin(2 * M_PI / 32), 1e-7);
}

TEST(CaoReader, ErrorsNameTheFileTheLineAndTheProblem) {
  auto message = [](const std::string& path) -> std::string {
    try {
      read_cao(path);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "no error";
  };
  auto expect_contains = [](const std::string& text, const std::string& part) {
    EXPECT_NE(text.find(part), std::string::npos) << "'" << part << "' not in: " << text;
  };
  const std::string missing = message(kData + "no_such_file.cao");
  expect_contains(missing, "no_such_file.cao");
  expect_contains(missing, "not found");

  const std::string header = "V1\n3\n0 0 0\n1 0 0\n0 1 0\n0\n0\n1\n";
  const std::string bad_index = message(temp_cao("bad_index", header + "3 0 1 7\n"));
  expect_contains(bad_index, "kct_cao_bad_index.cao");
  expect_contains(bad_index, "line 9");
  expect_contains(bad_index, "'7' is not in [0, 3)");

  expect_contains(message(temp_cao("too_few", header + "2 0 1\n")), "point count >= 3");
  expect_contains(message(temp_cao("short", header)), "end of file: expected face from points 0");
  expect_contains(message(temp_cao("nan", "V1\n1\n0 nan 0\n")), "'nan' is not a finite number");
  expect_contains(message(temp_cao("count", "V1\nthree\n")), "expected the number of points");
  expect_contains(message(temp_cao("trailing", header + "3 0 1 2\n0\n0\n5\n")),
                  "unexpected content after the circles section");
  expect_contains(message(temp_cao("lines_only", "V1\n2\n0 0 0\n1 0 0\n1\n0 1\n0\n0\n")),
                  "no faces");
  expect_contains(message(temp_cao("open_loop",
                                   "V1\n4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
                                   "3\n0 1\n1 2\n2 3\n1\n3 0 1 2\n0\n")),
                  "do not form a closed loop");
  const std::string self = ::testing::TempDir() + "/kct_cao_self.cao";
  write_text(self, "V1\nload(\"kct_cao_self.cao\")\n0\n0\n0\n0\n");
  expect_contains(message(self), "cycle");
  // load_mesh passes the reader's error on.
  EXPECT_THROW(load_mesh(temp_cao("mesh_bad", header + "3 0 1 7\n")), std::runtime_error);
  EXPECT_THROW(read_cao(kData + "cube.cao", 2), std::invalid_argument);
}

}  // namespace
}  // namespace kct
