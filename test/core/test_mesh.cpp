#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include "klt_contour_tracker/core/mesh.h"

namespace {

const std::string kDemoModel = std::string(KCT_SOURCE_DIR) + "/models/demo_crate.obj";

/// A fresh temporary folder, removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    path_ = std::filesystem::temp_directory_path() /
            ("kct_test_mesh_" +
             std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

/// Signed volume (divergence theorem); positive when faces are CCW seen from outside.
double signed_volume(const kct::Mesh& mesh) {
  double volume = 0.0;
  for (const auto& f : mesh.faces)
    volume += mesh.vertices[f[0]].dot(mesh.vertices[f[1]].cross(mesh.vertices[f[2]])) / 6.0;
  return volume;
}

/// Unit cube OBJ with 4 corners per face (24 'v' lines) and a UV chart per face, so every
/// edge is a UV seam: the loader must still merge the positions.
void write_seamed_cube(const std::string& path) {
  std::ofstream obj(path);
  const int quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                           {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  auto corner = [](int i) {
    return Eigen::Vector3d(((i & 1) ^ ((i >> 1) & 1)) ? 0.5 : -0.5, (i & 2) ? 0.5 : -0.5,
                           (i & 4) ? 0.5 : -0.5);
  };
  for (const auto& q : quads)
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d p = corner(q[k]);
      obj << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
    }
  obj << "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
  for (int f = 0; f < 6; ++f) {
    const int b = 4 * f + 1;
    obj << "f " << b << "/1 " << b + 1 << "/2 " << b + 2 << "/3 " << b + 3 << "/4\n";
  }
}

}  // namespace

TEST(Mesh, DemoModelIsClosedTexturedAndInMetres) {
  const kct::Mesh mesh = kct::load_mesh(kDemoModel);
  EXPECT_EQ(mesh.vertices.size(), 18u);
  EXPECT_EQ(mesh.faces.size(), 32u);
  ASSERT_TRUE(mesh.has_texture());
  EXPECT_EQ(mesh.texture.type(), CV_8UC3);
  EXPECT_EQ(mesh.corner_uvs.size(), 3 * mesh.faces.size());
  for (const auto& uv : mesh.corner_uvs) {
    EXPECT_GE(uv.minCoeff(), 0.0f);
    EXPECT_LE(uv.maxCoeff(), 1.0f);
  }

  // Closed 2-manifold: every edge of every face appears in exactly one shared edge.
  const auto edges = mesh.shared_edges();
  EXPECT_EQ(edges.size() * 2, mesh.faces.size() * 3);
  std::map<std::pair<int, int>, int> uses;
  for (const auto& f : mesh.faces)
    for (int k = 0; k < 3; ++k)
      ++uses[{std::min(f[k], f[(k + 1) % 3]), std::max(f[k], f[(k + 1) % 3])}];
  for (const auto& [edge, count] : uses) EXPECT_EQ(count, 2) << edge.first << "-" << edge.second;
  for (const auto& e : edges) {
    for (int face : {e.face0, e.face1}) {
      const auto& f = mesh.faces[face];
      EXPECT_TRUE((f.array() == e.v0).any() && (f.array() == e.v1).any());
    }
    EXPECT_NE(e.face0, e.face1);
  }

  // Box 0.12 x 0.08 x 0.06 with a 0.02 chamfer and a 0.04 x 0.04 x 0.025 block on top.
  EXPECT_NEAR(mesh.diameter(), std::sqrt(0.12 * 0.12 + 0.08 * 0.08 + 0.06 * 0.06), 1e-6);
  EXPECT_NEAR(signed_volume(mesh), 0.12 * 0.08 * 0.06 - 0.5 * 0.02 * 0.02 * 0.06 + 0.04 * 0.04 * 0.025,
              1e-9);
  EXPECT_LT((mesh.bounding_box_center() - Eigen::Vector3d(0, 0, 0.0125)).norm(), 1e-9);
  for (int f = 0; f < static_cast<int>(mesh.faces.size()); ++f)
    EXPECT_NEAR(mesh.face_normal(f).norm(), 1.0, 1e-12);
}

TEST(Mesh, BoundingBoxAndBoundingSphere) {
  kct::Mesh mesh;
  EXPECT_TRUE(mesh.bounding_box().isEmpty());
  mesh.vertices = {{0.0, 0.0, 0.0}, {0.1, 0.0, 0.0}, {0.0, 0.2, 0.0}, {0.0, 0.0, 0.3}};
  mesh.faces = {{0, 1, 2}, {0, 2, 3}};
  const Eigen::AlignedBox3d box = mesh.bounding_box();
  EXPECT_LT((box.min() - Eigen::Vector3d(0, 0, 0)).norm(), 1e-12);
  EXPECT_LT((box.max() - Eigen::Vector3d(0.1, 0.2, 0.3)).norm(), 1e-12);
  EXPECT_LT((mesh.bounding_box_center() - Eigen::Vector3d(0.05, 0.1, 0.15)).norm(), 1e-12);
  // Every vertex of this mesh is a box corner: all are half a diagonal from the centre.
  EXPECT_NEAR(mesh.radius_about(mesh.bounding_box_center()), 0.5 * std::sqrt(0.01 + 0.04 + 0.09), 1e-12);
  EXPECT_NEAR(mesh.radius_about(Eigen::Vector3d::Zero()), 0.3, 1e-12);
}

TEST(Mesh, ScaleFactorMultipliesCoordinates) {
  const kct::Mesh metres = kct::load_mesh(kDemoModel);
  const kct::Mesh millimetres = kct::load_mesh(kDemoModel, 1000.0);
  ASSERT_EQ(metres.vertices.size(), millimetres.vertices.size());
  for (std::size_t i = 0; i < metres.vertices.size(); ++i)
    EXPECT_LT((1000.0 * metres.vertices[i] - millimetres.vertices[i]).norm(), 1e-6);
  EXPECT_NEAR(millimetres.diameter(), 1000.0 * metres.diameter(), 1e-6);
  EXPECT_THROW(kct::load_mesh(kDemoModel, 0.0), std::runtime_error);
}

TEST(Mesh, MissingAndCorruptFilesThrowNamingThePath) {
  TempDir dir;
  const std::string missing = dir.file("does_not_exist.obj");
  try {
    kct::load_mesh(missing);
    FAIL() << "no exception for a missing file";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  for (const std::string name : {"corrupt.obj", "corrupt.stl", "corrupt.ply"}) {
    const std::string corrupt = dir.file(name);
    std::ofstream(corrupt) << "this is \x01\x02 not a mesh\nf 1 2\n";
    try {
      kct::load_mesh(corrupt);
      FAIL() << "no exception for " << name;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(corrupt), std::string::npos) << e.what();
    }
  }
}

TEST(Mesh, MergesPositionsAcrossUvSeams) {
  TempDir dir;
  const std::string path = dir.file("cube.obj");
  write_seamed_cube(path);
  const kct::Mesh cube = kct::load_mesh(path, 0.1);
  EXPECT_EQ(cube.vertices.size(), 8u);
  EXPECT_EQ(cube.faces.size(), 12u);
  EXPECT_EQ(cube.shared_edges().size(), 18u);
  EXPECT_FALSE(cube.has_texture());  // no material / image: UVs are dropped
  EXPECT_NEAR(signed_volume(cube), 1e-3, 1e-12);
  EXPECT_NEAR(cube.diameter(), 0.1 * std::sqrt(3.0), 1e-12);
}

TEST(Mesh, AppendMeshTransformsAndOffsets) {
  const kct::Mesh crate = kct::load_mesh(kDemoModel);
  kct::Mesh combined;
  kct::append_mesh(combined, crate, Eigen::Isometry3d::Identity());
  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  shift.translate(Eigen::Vector3d(0.5, 0, 0));
  kct::append_mesh(combined, crate, shift);
  ASSERT_EQ(combined.vertices.size(), 2 * crate.vertices.size());
  ASSERT_EQ(combined.faces.size(), 2 * crate.faces.size());
  const std::size_t n = crate.vertices.size();
  for (std::size_t i = 0; i < n; ++i)
    EXPECT_LT((combined.vertices[n + i] - crate.vertices[i] - Eigen::Vector3d(0.5, 0, 0)).norm(),
              1e-12);
  EXPECT_EQ(combined.faces[crate.faces.size()], crate.faces[0] + Eigen::Vector3i::Constant(n));
  EXPECT_TRUE(combined.has_texture());
  EXPECT_EQ(combined.texture.cols, 2 * crate.texture.cols);
  EXPECT_EQ(combined.shared_edges().size(), 2 * crate.shared_edges().size());
}

TEST(Mesh, DiameterOfLargeMeshes) {
  // UV sphere (exact diameter 2r) with far more than the brute-force vertex limit.
  kct::Mesh sphere;
  const int n_lat = 60, n_lon = 80;
  const double r = 0.1;
  for (int i = 0; i <= n_lat; ++i)
    for (int j = 0; j < n_lon; ++j) {
      const double th = M_PI * i / n_lat, ph = 2 * M_PI * j / n_lon;
      sphere.vertices.emplace_back(r * std::sin(th) * std::cos(ph),
                                   r * std::sin(th) * std::sin(ph), r * std::cos(th));
    }
  ASSERT_GT(sphere.vertices.size(), 4000u);
  EXPECT_LE(sphere.diameter(), 2 * r + 1e-12);
  EXPECT_GE(sphere.diameter(), 2 * r * 0.998);

  // Elongated point set: the pruned exact search must find the true pair.
  kct::Mesh rod;
  for (int i = 0; i < 5000; ++i) {
    const double t = i / 4999.0;
    rod.vertices.emplace_back(t, 0.01 * std::sin(37.0 * t), 0.01 * std::cos(91.0 * t));
  }
  double exact = 0.0;
  for (std::size_t i = 0; i < rod.vertices.size(); ++i)
    for (std::size_t j = i + 1; j < rod.vertices.size(); ++j)
      exact = std::max(exact, (rod.vertices[i] - rod.vertices[j]).norm());
  EXPECT_NEAR(rod.diameter(), exact, 1e-12);
}

// ---- Bad input (issue 8, findings 4 and 5) --------------------------------------------------

namespace {

/// A unit cube OBJ (8 shared corners, 12 triangles) offset by `offset`, plus `extra` lines.
void write_cube(const std::string& path, const Eigen::Vector3d& offset, const std::string& extra = "") {
  std::ofstream obj(path);
  obj.precision(17);
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d p =
        offset + Eigen::Vector3d(i & 1 ? 0.5 : -0.5, i & 2 ? 0.5 : -0.5, i & 4 ? 0.5 : -0.5);
    obj << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  }
  obj << "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\n"
         "f 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\n"
      << extra;
}

std::string load_error(const std::string& path, double scale = 1.0) {
  try {
    kct::load_mesh(path, scale);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// UBSan found a signed overflow in the vertex hash (cube shifted by 1e6 m) and an overflowing
// float -> int64 cast (larger offsets along one axis): cells are now counted from the bounding
// box. The scripts/test.sh sanitizer pass runs this test under UBSan.
TEST(Mesh, ModelsFarFromTheOriginMergeLikeAtTheOrigin) {
  TempDir dir;
  const std::string path = dir.file("far.obj");
  write_cube(path, Eigen::Vector3d(1e6, -1e6, 1e6));
  const kct::Mesh far = kct::load_mesh(path);
  EXPECT_EQ(far.vertices.size(), 8u);
  EXPECT_EQ(far.faces.size(), 12u);
  // 1e14 m along x: the x coordinates collapse in float, the mesh flattens (not an error of
  // ours); loading must end with a mesh or a clear error, and no undefined behaviour.
  write_cube(path, Eigen::Vector3d(1e14, 0, 0));
  const std::string error = load_error(path);
  if (!error.empty()) {
    EXPECT_NE(error.find(path), std::string::npos) << error;
  }
}

TEST(Mesh, ZeroAreaFacesAreDropped) {
  TempDir dir;
  const std::string path = dir.file("collinear.obj");
  // Three distinct collinear vertices forming one more (zero-area) face.
  write_cube(path, Eigen::Vector3d::Zero(), "v 2 0 0\nv 3 0 0\nv 4 0 0\nf 9 10 11\n");
  const kct::Mesh mesh = kct::load_mesh(path);
  EXPECT_EQ(mesh.faces.size(), 12u);
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    EXPECT_GT(mesh.face_normal(static_cast<int>(f)).norm(), 0.5);
}

TEST(Mesh, ImplausibleScalesNameTheScaleOption) {
  TempDir dir;
  const std::string path = dir.file("cube.obj");
  write_cube(path, Eigen::Vector3d::Zero());
  for (double scale : {1e300, 1e30, 1e-9}) {
    const std::string error = load_error(path, scale);
    EXPECT_NE(error.find("--model-scale"), std::string::npos) << scale << ": " << error;
    EXPECT_NE(error.find("allowed [0.0001, 10000] m"), std::string::npos) << error;
  }
  EXPECT_EQ(load_error(path, 0.001), "");
}

TEST(Mesh, HeadersPromisingMoreThanTheFileHoldsAreRejectedBeforeLoading) {
  TempDir dir;
  const std::string ply = dir.file("huge.ply");
  std::ofstream(ply) << "ply\nformat binary_little_endian 1.0\nelement vertex 100000000\n"
                        "property float x\nproperty float y\nproperty float z\n"
                        "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                     << std::string(64, '\0');
  const std::string ply_error = load_error(ply);
  EXPECT_NE(ply_error.find("PLY header declares"), std::string::npos) << ply_error;
  const std::string ascii = dir.file("huge_ascii.ply");
  std::ofstream(ascii) << "ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\n"
                          "property float x\nend_header\n0\n";
  EXPECT_NE(load_error(ascii).find("invalid count"), std::string::npos) << load_error(ascii);

  const std::string stl = dir.file("huge.stl");
  {
    std::ofstream out(stl, std::ios::binary);
    out << std::string(80, 'x');
    const uint32_t facets = 4000000000u;
    out.write(reinterpret_cast<const char*>(&facets), 4);
    out << std::string(100, '\0');
  }
  const std::string stl_error = load_error(stl);
  EXPECT_NE(stl_error.find("binary STL declares 4000000000 facets"), std::string::npos)
      << stl_error;
}

// assimp leaked when its ASCII STL reader threw (LeakSanitizer): malformed ASCII STL is now
// refused before assimp sees it; a well-formed one still loads.
TEST(Mesh, MalformedAsciiStlIsRefusedBeforeAssimp) {
  TempDir dir;
  const std::string good = dir.file("good.stl");
  std::ofstream(good) << "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                         "vertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
  EXPECT_EQ(load_error(good), "");
  const std::string bad = dir.file("bad.stl");
  std::ofstream(bad) << "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0\nendsolid\n";
  EXPECT_NE(load_error(bad).find("malformed ASCII STL"), std::string::npos) << load_error(bad);
}

// libFuzzer found a malformed OFF (a face line of NUL bytes) on which assimp's triangulation
// hits an ai_assert that aborts the process (the nodelet manager, for ~mesh_resource): OFF is
// now checked before assimp sees it.
TEST(Mesh, MalformedOffIsRefusedBeforeAssimpAborts) {
  TempDir dir;
  const std::string good = dir.file("tetra.off");
  std::ofstream(good) << "OFF\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  EXPECT_EQ(load_error(good), "");
  const std::string bad = dir.file("bad.off");
  std::ofstream(bad, std::ios::binary) << "OFF\n4 4 6\n0 0 0\n1 0 0\n0 0 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3"
                                       << std::string(12, '\0') << " 0 3 2\n3 1 2 3\n";
  EXPECT_NE(load_error(bad).find("malformed OFF"), std::string::npos) << load_error(bad);
  const std::string index = dir.file("index.off");
  std::ofstream(index) << "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
  EXPECT_NE(load_error(index).find("invalid vertex index '7'"), std::string::npos) << load_error(index);
}
