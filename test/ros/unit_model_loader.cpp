// Model loading for the nodelet: URDF links (several visuals with origins and scales, file://
// and package:// meshes, primitives), single mesh resources, and the errors for each broken
// input. ROS libraries, no master. The corrupt-mesh cases write small files to a gtest temp dir.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>

#include "klt_contour_tracker/ros/model_loader.h"
#include "klt_contour_tracker/ros/param_loader.h"

namespace {

using namespace klt_contour_tracker;

const std::string kObjPath = KCT_SOURCE_DIR "/models/demo_crate.obj";
const std::string kObjFile = "file://" + kObjPath;
const std::string kObjPackage = "package://klt_contour_tracker/models/demo_crate.obj";

// package:// needs the package on ROS_PACKAGE_PATH (set by devel/setup.bash; added here so the
// test also runs without it).
class ModelLoader : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const char* old = std::getenv("ROS_PACKAGE_PATH");
    const std::string path = std::string(KCT_SOURCE_DIR) + (old ? std::string(":") + old : "");
    setenv("ROS_PACKAGE_PATH", path.c_str(), 1);
  }
};

std::string urdf(const std::string& links) {
  return "<?xml version=\"1.0\"?><robot name=\"test_robot\">" + links + "</robot>";
}

std::string mesh_visual(const std::string& file, const std::string& scale, const std::string& xyz,
                        const std::string& rpy) {
  return "<visual><origin xyz=\"" + xyz + "\" rpy=\"" + rpy + "\"/><geometry><mesh filename=\"" +
         file + "\" scale=\"" + scale + "\"/></geometry></visual>";
}

// Expects std::runtime_error whose message contains every part.
template <typename F>
void expect_error(F&& f, std::initializer_list<std::string> parts) {
  try {
    f();
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    for (const auto& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << "'" << part << "' not in: " << e.what();
  }
}

// Signed volume (divergence theorem): positive when every face is CCW from outside.
double signed_volume(const kct::Mesh& mesh) {
  double v = 0.0;
  for (const auto& f : mesh.faces)
    v += mesh.vertices[f[0]].dot(mesh.vertices[f[1]].cross(mesh.vertices[f[2]])) / 6.0;
  return v;
}

std::string write_temp(const std::string& name, const std::string& content) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

TEST_F(ModelLoader, UrdfMergesVisualsWithOriginsAndScales) {
  const kct::Mesh reference = kct::load_mesh(kObjPath, 1.0);
  const std::string xml = urdf(
      "<link name=\"base\"/>"
      "<link name=\"crate\">" +
      mesh_visual(kObjFile, "1 1 1", "0 0 0", "0 0 0") +
      mesh_visual(kObjPackage, "0.5 0.5 0.5", "0.2 -0.1 0.05", "0 0 1.5707963267948966") +
      "</link><joint name=\"j\" type=\"fixed\"><parent link=\"base\"/><child link=\"crate\"/>"
      "</joint>");
  const kct::Mesh mesh = load_model_from_urdf(xml, "crate");
  const std::size_t n = reference.vertices.size();
  ASSERT_EQ(mesh.vertices.size(), 2 * n);
  ASSERT_EQ(mesh.faces.size(), 2 * reference.faces.size());
  Eigen::Isometry3d second = Eigen::Isometry3d::Identity();
  second.translation() = Eigen::Vector3d(0.2, -0.1, 0.05);
  second.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_LT((mesh.vertices[i] - reference.vertices[i]).norm(), 1e-9);
    EXPECT_LT((mesh.vertices[n + i] - second * (0.5 * reference.vertices[i])).norm(), 1e-9) << i;
  }
  EXPECT_NEAR(signed_volume(mesh), 1.125 * signed_volume(reference), 1e-9);
  EXPECT_TRUE(mesh.has_texture());  // the .mtl and texture next to the .obj were found
}

TEST_F(ModelLoader, DemoCrateUrdfMatchesTheMesh) {
  std::ifstream file(KCT_SOURCE_DIR "/models/demo_crate.urdf");
  const std::string xml((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  const kct::Mesh mesh = load_model_from_urdf(xml, "crate");
  const kct::Mesh reference = kct::load_mesh(kObjPath, 1.0);
  EXPECT_EQ(mesh.faces.size(), reference.faces.size());
  EXPECT_NEAR(mesh.diameter(), reference.diameter(), 1e-12);
}

TEST_F(ModelLoader, UrdfPrimitivesAndNonUniformScale) {
  const std::string xml = urdf(
      "<link name=\"object\">"
      "<visual><origin xyz=\"0 0 0.1\"/><geometry><box size=\"0.1 0.2 0.3\"/></geometry>"
      "<material name=\"red\"><color rgba=\"1 0 0 1\"/></material></visual>"
      "<visual><origin xyz=\"0.5 0 0\"/><geometry><cylinder radius=\"0.05\" length=\"0.2\"/>"
      "</geometry></visual>"
      "<visual><origin xyz=\"-0.5 0 0\"/><geometry><sphere radius=\"0.04\"/></geometry></visual>"
      "</link>");
  const kct::Mesh mesh = load_model_from_urdf(xml, "object");
  const double volume = 0.1 * 0.2 * 0.3 + M_PI * 0.05 * 0.05 * 0.2 + 4.0 / 3.0 * M_PI * 0.04 * 0.04 * 0.04;
  EXPECT_NEAR(signed_volume(mesh), volume, 0.02 * volume);  // tessellated: within 2 %
  EXPECT_EQ(mesh.base_color, cv::Vec3b(0, 0, 255));  // the first visual's red, BGR

  // Non-uniform and mirroring mesh scales: vertices scaled per axis, faces still outward.
  const kct::Mesh reference = kct::load_mesh(kObjPath, 1.0);
  for (const std::string scale : {"1 2 0.5", "-1 1 1"}) {
    const kct::Mesh scaled = load_model_from_urdf(
        urdf("<link name=\"a\">" + mesh_visual(kObjFile, scale, "0 0 0", "0 0 0") + "</link>"), "a");
    const Eigen::Vector3d s = scale == "-1 1 1" ? Eigen::Vector3d(-1, 1, 1) : Eigen::Vector3d(1, 2, 0.5);
    ASSERT_EQ(scaled.vertices.size(), reference.vertices.size());
    EXPECT_LT((scaled.vertices[3] - reference.vertices[3].cwiseProduct(s)).norm(), 1e-12);
    EXPECT_NEAR(signed_volume(scaled), std::abs(s.prod()) * signed_volume(reference), 1e-9) << scale;
  }
}

TEST_F(ModelLoader, PrimitivesAreClosedAndOutward) {
  const kct::Mesh box = make_box_mesh({0.1, 0.2, 0.3});
  EXPECT_EQ(box.vertices.size(), 8u);
  EXPECT_EQ(box.faces.size(), 12u);
  EXPECT_EQ(box.shared_edges().size(), 18u);  // closed: every edge shared by two faces
  EXPECT_NEAR(signed_volume(box), 0.006, 1e-12);
  EXPECT_NEAR(box.diameter(), std::sqrt(0.01 + 0.04 + 0.09), 1e-12);

  const kct::Mesh cylinder = make_cylinder_mesh(0.05, 0.2, 48);
  EXPECT_EQ(cylinder.faces.size(), 4u * 48u);
  EXPECT_EQ(cylinder.shared_edges().size(), 3 * cylinder.faces.size() / 2);
  for (int f = 0; f < static_cast<int>(cylinder.faces.size()); ++f) {
    const auto& t = cylinder.faces[f];
    const Eigen::Vector3d c = (cylinder.vertices[t[0]] + cylinder.vertices[t[1]] + cylinder.vertices[t[2]]) / 3;
    EXPECT_GT(cylinder.face_normal(f).dot(c), 0.0) << f;
  }
  const kct::Mesh sphere = make_sphere_mesh(0.04, 3);
  EXPECT_EQ(sphere.faces.size(), 1280u);
  for (const auto& v : sphere.vertices) EXPECT_NEAR(v.norm(), 0.04, 1e-12);
  EXPECT_GT(signed_volume(sphere), 0.0);

  EXPECT_THROW(make_box_mesh({0.1, 0.0, 0.1}), std::runtime_error);
  EXPECT_THROW(make_cylinder_mesh(-1.0, 0.1), std::runtime_error);
}

TEST_F(ModelLoader, UrdfErrorsNameTheProblem) {
  const std::string good = urdf("<link name=\"base\"/><link name=\"crate\">" +
                                mesh_visual(kObjFile, "1 1 1", "0 0 0", "0 0 0") +
                                "</link><joint name=\"j\" type=\"fixed\"><parent link=\"base\"/>"
                                "<child link=\"crate\"/></joint>");
  expect_error([&] { load_model_from_urdf(good, "box"); },
               {"no link 'box'", "links: base, crate"});
  expect_error([&] { load_model_from_urdf(good, "base"); }, {"link 'base' has no <visual>"});
  expect_error([&] { load_model_from_urdf("<robot name=", "crate"); }, {"cannot parse the URDF"});
  expect_error([&] { load_model_from_urdf("", "crate"); }, {"empty"});
  const std::string missing_package = urdf(
      "<link name=\"a\">" +
      mesh_visual("package://no_such_package_kct/meshes/x.stl", "1 1 1", "0 0 0", "0 0 0") +
      "</link>");
  expect_error([&] { load_model_from_urdf(missing_package, "a"); },
               {"link 'a', visual 0", "package 'no_such_package_kct' not found"});
  const std::string missing_file = urdf(
      "<link name=\"a\">" +
      mesh_visual("package://klt_contour_tracker/models/nothing.obj", "1 1 1", "0 0 0", "0 0 0") +
      "</link>");
  expect_error([&] { load_model_from_urdf(missing_file, "a"); },
               {"models/nothing.obj", "no such file"});
}

TEST_F(ModelLoader, ResourceErrorsNameTheUrl) {
  const std::string corrupt = write_temp("kct_corrupt.stl", "solid x\nfacet normal garbage\n");
  expect_error([&] { load_model_from_resource("file://" + corrupt, 1.0); },
               {"'file://" + corrupt + "'"});
  const std::string no_faces = write_temp("kct_no_faces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
  expect_error([&] { load_model_from_resource(no_faces, 1.0); }, {no_faces});
  expect_error([&] { load_model_from_resource(kObjFile, 0.0); }, {"scale"});
  expect_error([&] { load_model_from_resource("file:///nonexistent/kct/x.obj", 1.0); },
               {"no such file: /nonexistent/kct/x.obj"});
  expect_error([&] { load_model_from_resource("package:///x.obj", 1.0); }, {"no package name"});
}

TEST_F(ModelLoader, ResourcesByPathFileAndPackageAgree) {
  const kct::Mesh a = load_model_from_resource(kObjPath, 0.001);
  const kct::Mesh b = load_model_from_resource(kObjFile, 0.001);
  const kct::Mesh c = load_model_from_resource(kObjPackage, 0.001);
  const std::string resolved = resolve_resource_path(kObjPackage);
  EXPECT_EQ(std::ifstream(resolved).good(), true) << resolved;
  EXPECT_NE(resolved.find("/models/demo_crate.obj"), std::string::npos) << resolved;
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.vertices.size(), c.vertices.size());
  for (std::size_t i = 0; i < a.vertices.size(); ++i) {
    EXPECT_EQ(a.vertices[i], b.vertices[i]);
    EXPECT_EQ(a.vertices[i], c.vertices[i]);
  }
  EXPECT_NEAR(a.diameter(), 0.001 * kct::load_mesh(kObjPath).diameter(), 1e-15);
  EXPECT_TRUE(c.has_texture());
  EXPECT_EQ(resolve_resource_path("http://example.invalid/x.stl"), "");
}

TEST_F(ModelLoader, ConfigErrorsStartWithTheParameter) {
  NodeletConfig config;
  config.mesh_resource = "file:///nonexistent/kct/x.obj";
  expect_error([&] { load_model(config); }, {"~mesh_resource: ", "no such file"});
  config.model_description = urdf("<link name=\"a\"/>");
  config.object_link = "b";
  expect_error([&] { load_model(config); }, {"~model_description: ", "no link 'b'"});
  config.object_link = "a";
  expect_error([&] { load_model(config); }, {"~model_description: ", "no <visual>"});
  config.model_description.clear();
  config.mesh_resource = kObjPackage;
  config.mesh_scale = 2.0;
  EXPECT_NEAR(load_model(config).diameter(), 2.0 * kct::load_mesh(kObjPath).diameter(), 1e-12);
}

}  // namespace
