#pragma once
/// \file contour_extractor.h
/// Model contour and sharp-edge detection for a pose (paper Sec. 3.5, supplement Sec. 3,
/// Algorithm 1), with self-occlusion handled by the precomputed VisibilityTable.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/visibility_table.h"

namespace kct {

/// Type of a mesh edge in a given pose (Algorithm 1).
enum class EdgeType : std::uint8_t {
  kOther,    ///< not drawn
  kContour,  ///< one face front-facing and visible, the other back-facing (outer contour),
             ///< or a boundary edge (one face) whose face is front-facing and visible
  kSharp,    ///< both faces front-facing and visible, normals more than alpha apart
};

/// A projected Contour or Sharp edge, image pixels (pixel centres at integer coordinates).
struct ContourSegment {
  Eigen::Vector2d a_px, b_px;
  EdgeType type;
  int edge = -1;  ///< index into ContourExtractor::edges()
};

/// Classifies the mesh's edges for a pose and projects the Contour and Sharp ones.
///
/// Any mesh is accepted, closed or not (CAD exports are often open: a floor polygon, walls).
/// Algorithm 1 is defined for an edge shared by two faces; the extension to other edges:
/// - a boundary edge (one face) is Contour when its face is front-facing and visible: beyond it
///   there is no surface, so it is an outline (a single polygon seen from its front side is
///   outlined by all its edges);
/// - a non-manifold edge (3+ faces, e.g. a wall standing on a floor polygon) is Contour when
///   one of its faces is front-facing and visible and another is back-facing (the two-face rule
///   applied to any pair), else Sharp when two of its visible front faces have normals more
///   than alpha apart.
/// Degenerate faces (zero area) are ignored, except that a two-face edge with a degenerate face
/// stays kOther as before (a sliver inside a closed surface must not create an outline).
///
/// Front-facing test: Algorithm 1 evaluates v . n < 0 with v a face vertex in camera
/// coordinates. Since (R v + t) . (R n) = (v - c) . n with c = -R^T t the camera centre in
/// the object frame, the test is done once per face in the object frame as n . c > n . v
/// (no per-vertex transform; using any vertex of the planar face instead of the opposite
/// vertex v1 / v2 gives the same value).
///
/// Not thread-safe: the const methods reuse internal scratch buffers and cache the last
/// invisible-face set S (consecutive evaluations mostly fall into the same icosphere face).
/// Use one instance per thread.
class ContourExtractor {
 public:
  /// `visibility` may be null: then no face counts as invisible (S is empty, no
  /// self-occlusion handling). `sharp_edge_angle_deg` is the paper's alpha (45 deg), in
  /// [0, 180]. Throws std::invalid_argument for a null mesh, a bad angle or a visibility table
  /// built for another face count.
  ContourExtractor(std::shared_ptr<const Mesh> mesh,
                   std::shared_ptr<const VisibilityTable> visibility,
                   double sharp_edge_angle_deg);

  /// Type of every edge of edges() (same order) for the pose (Algorithm 1).
  void classify(const Pose& object_to_camera, std::vector<EdgeType>& types) const;

  /// The Contour and Sharp edges projected with the ideal pinhole model; edges with an end
  /// point at camera depth z <= 1e-6 m are skipped. Segments are not clipped to the image.
  /// Same result as classify(), faster on large meshes: one pass over all edges selects the
  /// edges that can be Contour or Sharp while the camera centre stays within 10% of its
  /// distance to the object (faces that cannot change side are skipped), and later calls in
  /// that range classify only those (exact: see rebuild_candidates()).
  std::vector<ContourSegment> extract(const Pose& object_to_camera,
                                      const PinholeCamera& camera) const;
  /// Same, into `segments` (cleared first; its capacity is reused: no allocation once warm).
  void extract(const Pose& object_to_camera, const PinholeCamera& camera,
               std::vector<ContourSegment>& segments) const;

  /// Every mesh edge with at least one face. Edges shared by two faces come first, in
  /// Mesh::shared_edges() order; then boundary edges (face1 == -1) and non-manifold edges
  /// (face0, face1: their first two faces), sorted by vertex pair.
  const std::vector<MeshEdge>& edges() const { return edges_; }
  const Mesh& mesh() const { return *mesh_; }
  /// Null when constructed without a table.
  const std::shared_ptr<const VisibilityTable>& visibility() const { return visibility_; }
  double sharp_edge_angle_deg() const { return sharp_edge_angle_deg_; }

 private:
  /// Per face, the outward unit normal n and n . v for a vertex v (object frame).
  struct FacePlane {
    Eigen::Vector3d normal;
    double offset;
  };
  struct EdgeInfo {
    int p, q;          // end points (vertex indices)
    int face1, face2;  // adjacent faces (v1, q, p) and (v2, p, q) of Algorithm 1; face2 == -1
                       // for a boundary edge, both -1 for a non-manifold edge
    bool sharp;        // dihedral test: face normals more than alpha apart
    bool usable;       // false when a face is degenerate (zero area): always kOther
    int extra_begin = 0, extra_end = 0;  // non-manifold: its faces in extra_faces_
  };
  /// Algorithm 1 and its extension to boundary / non-manifold edges; `state(face)` gives the
  /// face's kFront / kFrontVisible bits.
  template <typename State>
  EdgeType edge_type(const EdgeInfo& e, const State& state) const;
  /// Fills face_state_: bit 0 front-facing, bit 1 front-facing and not in S.
  void compute_face_states(const Pose& object_to_camera) const;
  /// The visibility table's bits of the faces hidden from a camera centred at `camera_object`
  /// (object frame, m), cached per icosphere face; null without a table.
  const std::uint64_t* invisible_bits(const Eigen::Vector3d& camera_object) const;
  /// Face f's kFront / kFrontVisible bits for that camera (`invisible` from invisible_bits()).
  std::uint8_t face_state(int f, const Eigen::Vector3d& camera_object,
                          const std::uint64_t* invisible) const;
  /// Selects candidates_ for camera centres within candidate_radius_ of `camera_object`.
  void rebuild_candidates(const Eigen::Vector3d& camera_object) const;

  std::shared_ptr<const Mesh> mesh_;
  std::shared_ptr<const VisibilityTable> visibility_;
  double sharp_edge_angle_deg_;
  std::vector<MeshEdge> edges_;
  std::vector<EdgeInfo> edge_info_;
  std::vector<FacePlane> face_planes_;
  std::vector<int> extra_faces_;  // faces of non-manifold edges (non-degenerate only)
  double cos_alpha_ = 1.0;

  mutable int cached_icosphere_face_ = -1;
  mutable VisibilityTable::Bits cached_invisible_;
  mutable std::vector<std::uint8_t> face_state_;
  mutable std::vector<int> candidates_;  ///< edge indices, ascending
  mutable Eigen::Vector3d candidate_camera_ = Eigen::Vector3d::Zero();
  mutable double candidate_radius_ = -1.0;  ///< < 0: no candidates selected yet
};

}  // namespace kct
