#include "klt_contour_tracker/ros/model_loader.h"

#include <resource_retriever/retriever.h>
#include <ros/package.h>
#include <urdf/model.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "klt_contour_tracker/core/icosphere.h"
#include "klt_contour_tracker/ros/param_loader.h"

namespace klt_contour_tracker {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& what) { throw std::runtime_error(what); }

bool starts_with(const std::string& s, const std::string& prefix) {
  return s.rfind(prefix, 0) == 0;
}

// Faces of a convex primitive centred on the origin are turned to face away from it, so the
// tessellation code need not track the winding of every triangle by hand.
void orient_outwards(kct::Mesh& mesh) {
  for (auto& f : mesh.faces) {
    const Eigen::Vector3d& a = mesh.vertices[f[0]];
    const Eigen::Vector3d& b = mesh.vertices[f[1]];
    const Eigen::Vector3d& c = mesh.vertices[f[2]];
    if ((b - a).cross(c - a).dot(a + b + c) < 0.0) std::swap(f[1], f[2]);
  }
}

void require_positive(double value, const std::string& what) {
  if (!(value > 0.0) || !std::isfinite(value))
    fail(what + " must be positive and finite, got " + std::to_string(value));
}

// Downloads a resource resource_retriever can fetch (http://...) into a temporary directory,
// under its own file name so that assimp picks the importer by the extension, and loads it.
kct::Mesh load_remote(const std::string& url) {
  resource_retriever::MemoryResource memory;
  try {
    memory = resource_retriever::Retriever().get(url);
  } catch (const resource_retriever::Exception& e) {
    fail("'" + url + "': cannot retrieve: " + e.what());
  }
  std::string dir_template = (fs::temp_directory_path() / "klt_contour_tracker_XXXXXX").string();
  if (!mkdtemp(dir_template.data())) fail("'" + url + "': cannot create a temporary directory");
  const fs::path dir(dir_template);
  std::string name = url.substr(url.find_last_of('/') + 1);
  name = name.substr(0, name.find_first_of("?#"));
  const fs::path file = dir / (name.empty() ? std::string("mesh") : name);
  kct::Mesh mesh;
  std::string error;
  {
    std::ofstream out(file, std::ios::binary);
    out.write(reinterpret_cast<const char*>(memory.data.get()),
              static_cast<std::streamsize>(memory.size));
    if (!out) error = "cannot write the download to " + file.string();
  }
  if (error.empty()) {
    try {
      mesh = kct::load_mesh(file.string(), 1.0);
    } catch (const std::exception& e) {
      error = e.what();
    }
  }
  std::error_code ignored;
  fs::remove_all(dir, ignored);
  if (!error.empty()) fail("'" + url + "': " + error);
  return mesh;
}

kct::Mesh load_primitive(const urdf::Geometry& geometry) {
  switch (geometry.type) {
    case urdf::Geometry::BOX: {
      const auto& box = static_cast<const urdf::Box&>(geometry);
      return make_box_mesh({box.dim.x, box.dim.y, box.dim.z});
    }
    case urdf::Geometry::CYLINDER: {
      const auto& cylinder = static_cast<const urdf::Cylinder&>(geometry);
      return make_cylinder_mesh(cylinder.radius, cylinder.length);
    }
    case urdf::Geometry::SPHERE:
      return make_sphere_mesh(static_cast<const urdf::Sphere&>(geometry).radius);
    default:
      fail("unknown geometry type " + std::to_string(static_cast<int>(geometry.type)));
  }
}

Eigen::Isometry3d to_isometry(const urdf::Pose& pose) {
  double x, y, z, w;
  pose.rotation.getQuaternion(x, y, z, w);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
  t.translation() = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  return t;
}

}  // namespace

std::string resolve_resource_path(const std::string& url) {
  std::string path;
  if (starts_with(url, "file://")) {
    path = url.substr(7);
  } else if (starts_with(url, "package://")) {
    const std::string rest = url.substr(10);
    const std::size_t slash = rest.find('/');
    const std::string package = rest.substr(0, slash);
    if (package.empty()) fail("'" + url + "': no package name");
    const std::string package_path = ros::package::getPath(package);
    if (package_path.empty())
      fail("'" + url + "': package '" + package + "' not found (ROS_PACKAGE_PATH)");
    path = slash == std::string::npos ? package_path : package_path + rest.substr(slash);
  } else if (url.find("://") == std::string::npos) {
    path = url;
  } else {
    return "";
  }
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    fail("'" + url + "': " + (fs::exists(path, ec) ? "not a regular file: " : "no such file: ") +
         path);
  return path;
}

kct::Mesh load_model_from_resource(const std::string& url, const Eigen::Vector3d& scale) {
  for (int i = 0; i < 3; ++i)
    if (!(scale[i] != 0.0) || !std::isfinite(scale[i]))
      fail("'" + url + "': scale must be non-zero and finite, got " + std::to_string(scale[i]));
  if (url.empty()) fail("empty resource name");
  const std::string path = resolve_resource_path(url);
  kct::Mesh mesh;
  if (path.empty()) {
    mesh = load_remote(url);
  } else {
    try {
      mesh = kct::load_mesh(path, 1.0);
    } catch (const std::exception& e) {
      fail("'" + url + "': " + e.what());
    }
  }
  if (mesh.faces.empty()) fail("'" + url + "': the mesh has no faces");
  for (auto& v : mesh.vertices) v = v.cwiseProduct(scale);
  if (scale.prod() < 0.0) {
    // A mirroring scale turns the faces inside out: restore counter-clockwise from outside.
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
      std::swap(mesh.faces[f][1], mesh.faces[f][2]);
      if (mesh.corner_uvs.size() == 3 * mesh.faces.size())
        std::swap(mesh.corner_uvs[3 * f + 1], mesh.corner_uvs[3 * f + 2]);
    }
  }
  return mesh;
}

kct::Mesh load_model_from_resource(const std::string& url, double scale) {
  if (!(scale > 0.0) || !std::isfinite(scale))
    fail("'" + url + "': scale must be positive and finite, got " + std::to_string(scale));
  return load_model_from_resource(url, Eigen::Vector3d::Constant(scale));
}

kct::Mesh load_model_from_urdf(const std::string& urdf_xml, const std::string& link_name) {
  urdf::Model model;
  if (urdf_xml.empty()) fail("the URDF is empty");
  if (!model.initString(urdf_xml)) fail("cannot parse the URDF (see the urdfdom error above)");
  const urdf::LinkConstSharedPtr link = model.getLink(link_name);
  if (!link) {
    std::vector<urdf::LinkSharedPtr> links;
    model.getLinks(links);
    std::string names;
    for (const auto& l : links) names += (names.empty() ? "" : ", ") + l->name;
    fail("robot '" + model.getName() + "' has no link '" + link_name + "' (links: " + names + ")");
  }
  std::vector<urdf::VisualSharedPtr> visuals = link->visual_array;
  if (visuals.empty() && link->visual) visuals.push_back(link->visual);
  if (visuals.empty()) fail("link '" + link_name + "' has no <visual>");

  kct::Mesh merged;
  for (std::size_t i = 0; i < visuals.size(); ++i) {
    const urdf::Visual& visual = *visuals[i];
    const std::string where = "link '" + link_name + "', visual " + std::to_string(i) +
                              (visual.name.empty() ? "" : " '" + visual.name + "'");
    if (!visual.geometry) fail(where + ": no <geometry>");
    kct::Mesh part;
    try {
      if (visual.geometry->type == urdf::Geometry::MESH) {
        const auto& mesh = static_cast<const urdf::Mesh&>(*visual.geometry);
        part = load_model_from_resource(mesh.filename,
                                        Eigen::Vector3d(mesh.scale.x, mesh.scale.y, mesh.scale.z));
      } else {
        part = load_primitive(*visual.geometry);
        if (visual.material && visual.material->color.a > 0.0f) {
          const urdf::Color& c = visual.material->color;
          auto to_byte = [](float v) {
            return static_cast<unsigned char>(std::lround(255.0 * std::min(1.0f, std::max(0.0f, v))));
          };
          part.base_color = cv::Vec3b(to_byte(c.b), to_byte(c.g), to_byte(c.r));
        }
      }
    } catch (const std::exception& e) {
      fail(where + ": " + e.what());
    }
    kct::append_mesh(merged, part, to_isometry(visual.origin));
  }
  return merged;
}

kct::Mesh load_model(const NodeletConfig& config) {
  if (!config.model_description.empty()) {
    try {
      return load_model_from_urdf(config.model_description, config.object_link);
    } catch (const std::exception& e) {
      fail(std::string("~model_description: ") + e.what());
    }
  }
  try {
    return load_model_from_resource(config.mesh_resource, config.mesh_scale);
  } catch (const std::exception& e) {
    fail(std::string("~mesh_resource: ") + e.what());
  }
}

kct::Mesh make_box_mesh(const Eigen::Vector3d& size) {
  for (int i = 0; i < 3; ++i) require_positive(size[i], "box size");
  kct::Mesh mesh;
  for (int i = 0; i < 8; ++i)
    mesh.vertices.emplace_back((i & 1 ? 0.5 : -0.5) * size.x(), (i & 2 ? 0.5 : -0.5) * size.y(),
                               (i & 4 ? 0.5 : -0.5) * size.z());
  // Each side as two triangles over its four corners (vertex index bits: x=1, y=2, z=4).
  const int sides[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  for (const auto& s : sides) {
    mesh.faces.emplace_back(s[0], s[1], s[2]);
    mesh.faces.emplace_back(s[0], s[2], s[3]);
  }
  orient_outwards(mesh);
  return mesh;
}

kct::Mesh make_cylinder_mesh(double radius, double length, int segments) {
  require_positive(radius, "cylinder radius");
  require_positive(length, "cylinder length");
  if (segments < 3) fail("a cylinder needs at least 3 segments");
  kct::Mesh mesh;
  for (int i = 0; i < segments; ++i) {
    const double a = 2.0 * M_PI * i / segments;
    mesh.vertices.emplace_back(radius * std::cos(a), radius * std::sin(a), -0.5 * length);
    mesh.vertices.emplace_back(radius * std::cos(a), radius * std::sin(a), 0.5 * length);
  }
  const int bottom = static_cast<int>(mesh.vertices.size());
  mesh.vertices.emplace_back(0.0, 0.0, -0.5 * length);
  mesh.vertices.emplace_back(0.0, 0.0, 0.5 * length);
  for (int i = 0; i < segments; ++i) {
    const int b0 = 2 * i, t0 = 2 * i + 1;
    const int b1 = 2 * ((i + 1) % segments), t1 = b1 + 1;
    mesh.faces.emplace_back(b0, b1, t1);
    mesh.faces.emplace_back(b0, t1, t0);
    mesh.faces.emplace_back(bottom, b1, b0);
    mesh.faces.emplace_back(bottom + 1, t0, t1);
  }
  orient_outwards(mesh);
  return mesh;
}

kct::Mesh make_sphere_mesh(double radius, int subdivisions) {
  require_positive(radius, "sphere radius");
  const kct::Icosphere sphere(subdivisions);
  kct::Mesh mesh;
  for (const auto& v : sphere.vertices()) mesh.vertices.push_back(radius * v);
  mesh.faces = sphere.faces();
  orient_outwards(mesh);
  return mesh;
}

}  // namespace klt_contour_tracker
