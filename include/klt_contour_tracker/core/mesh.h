#pragma once
/// \file mesh.h
/// Triangle mesh of the tracked object, in the object frame, in metres.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace kct {

/// Edge of the mesh with its faces (used for contour / sharp-edge detection).
struct MeshEdge {
  int v0, v1;      ///< vertex indices of the edge's end points
  int face0, face1;  ///< the two faces sharing the edge; face1 == -1 for a boundary edge
                     ///< (ContourExtractor::edges() only; shared_edges() has two faces always)
};

/// Triangulated mesh with vertices merged by position, so that every interior edge is shared
/// by two faces. Faces are counter-clockwise seen from outside (front side).
struct Mesh {
  std::vector<Eigen::Vector3d> vertices;  ///< object frame, metres
  std::vector<Eigen::Vector3i> faces;     ///< vertex indices, CCW from outside
  /// Optional texture coordinates per face corner (3 per face, OpenGL convention: v up).
  std::vector<Eigen::Vector2f> corner_uvs;
  cv::Mat texture;  ///< optional BGR 8-bit texture; empty when untextured
  cv::Vec3b base_color{180, 180, 180};  ///< BGR colour used when there is no texture

  bool has_texture() const { return !texture.empty() && corner_uvs.size() == faces.size() * 3; }
  /// Largest distance between two vertices (the paper's object size / diameter d), metres.
  double diameter() const;
  /// Axis-aligned bounding box of the vertices, object frame, metres (empty without vertices).
  Eigen::AlignedBox3d bounding_box() const;
  /// Centre of the axis-aligned bounding box, object frame, metres.
  Eigen::Vector3d bounding_box_center() const;
  /// Largest distance of a vertex from `center_object`, metres: the radius of the bounding
  /// sphere about that centre.
  double radius_about(const Eigen::Vector3d& center_object) const;
  /// Unit outward normal of a face (from its CCW winding).
  Eigen::Vector3d face_normal(int face) const;
  /// Edges shared by exactly two faces (boundary and non-manifold edges are skipped).
  std::vector<MeshEdge> shared_edges() const;
};

/// Loads any format assimp reads (OBJ, STL, PLY, DAE, glTF...) and ViSP's `.cao` (read_cao(),
/// cao_reader.h; cylinders and circles triangulated), triangulates, merges vertices
/// at the same position (within 1e-6 of the model size), multiplies coordinates by `scale`
/// (e.g. 0.001 for a model in millimetres) and loads the first diffuse texture found next to
/// the file. Throws std::runtime_error naming the file and the reason on failure.
Mesh load_mesh(const std::string& path, double scale = 1.0);

/// Appends `other` (transformed by `transform`) to `mesh`; used to merge several URDF visuals.
void append_mesh(Mesh& mesh, const Mesh& other, const Eigen::Isometry3d& transform);

}  // namespace kct
