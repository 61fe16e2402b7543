#pragma once
/// \file icosphere.h
/// Unit icosphere (recursively subdivided icosahedron) whose vertices are the preprocessed
/// viewpoint directions of the face-visibility table (paper Sec. 3.5 and supplement Sec. 3).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

namespace kct {

/// Icosphere of unit radius centred at the origin. Level 0 is the icosahedron (12 vertices,
/// 20 faces); every subdivision splits each face into 4 (edge midpoints pushed onto the
/// sphere): n subdivisions give 10 * 4^n + 2 vertices and 20 * 4^n faces (4 -> 2562 / 5120).
///
/// Face lookup descends the subdivision hierarchy: the 20 root spherical triangles are tested,
/// then at each level the 4 children of the current face (20 + 4 * n triangle tests, about
/// 0.1 us for n = 4). Because subdivision midpoints lie on the parent's great-circle edges,
/// the children's spherical triangles tile their parent exactly, so the descent finds the
/// same face as a brute-force search, needs no lookup grid and no extra memory beyond the
/// hierarchy's edge planes (about 6800 faces x 3 planes for n = 4).
class Icosphere {
 public:
  /// Builds the icosphere; throws std::invalid_argument unless 0 <= subdivisions <= 7.
  explicit Icosphere(int subdivisions);

  int subdivisions() const { return subdivisions_; }
  /// Unit vertex directions (the finest level's vertices include every coarser level's).
  const std::vector<Eigen::Vector3d>& vertices() const { return vertices_; }
  /// Faces of the finest level: vertex indices, counter-clockwise seen from outside.
  const std::vector<Eigen::Vector3i>& faces() const { return levels_.back().faces; }

  /// Index into faces() of the face whose spherical triangle contains `direction` (any
  /// non-zero vector; need not be normalized). On a shared edge or vertex one of the
  /// touching faces is returned. Returns 0 for a zero or non-finite direction.
  int face_containing(const Eigen::Vector3d& direction) const;

  /// Vertex indices of the face returned by face_containing().
  Eigen::Vector3i face_vertices_containing(const Eigen::Vector3d& direction) const {
    return faces()[face_containing(direction)];
  }

 private:
  struct Level {
    std::vector<Eigen::Vector3i> faces;
    /// Per face, the unit normals of the planes through the origin and each edge (a, b),
    /// (b, c), (c, a), pointing into the face: direction d is inside iff all 3 dots >= 0.
    std::vector<Eigen::Matrix3d> edge_planes;  // rows are the three plane normals
  };
  int subdivisions_;
  std::vector<Eigen::Vector3d> vertices_;
  std::vector<Level> levels_;  // levels_[l].faces[4 f + k] is child k of levels_[l-1].faces[f]
};

}  // namespace kct
