#pragma once
/// \file visibility_table.h
/// Precomputed face visibility from the icosphere's viewpoint directions (paper Sec. 3.5,
/// supplement Sec. 3 "Face Visibility Pre-calculation" / "Face Visibility in Current Pose").

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "klt_contour_tracker/core/icosphere.h"
#include "klt_contour_tracker/core/mesh.h"

namespace kct {

/// For every icosphere vertex u (viewpoint in direction u from the mesh's bounding-box centre,
/// looking along -u), the set S_u of mesh faces that do not appear in an orthographic
/// face-index render of `resolution_px` square pixels. A face seen by at least one pixel
/// counts as visible, so faces smaller than a pixel may land in S_u although they are
/// visible (the paper's method). Immutable once built; safe to share between threads.
class VisibilityTable {
 public:
  /// Bitset over the mesh faces: bit f of word f / 64 is set when face f is invisible.
  using Bits = std::vector<std::uint64_t>;

  /// Renders the mesh from every vertex of an icosphere with `subdivisions` (4 -> 2562 views)
  /// at `resolution_px`, in parallel over views. When `cache_dir` is non-empty the table is
  /// read from / written to `cache_file_path(...)` (directory created if needed); a missing,
  /// corrupt or mismatching file is rebuilt and rewritten. Throws std::invalid_argument for an
  /// empty mesh or bad settings (subdivisions outside [0, 7], resolution_px outside
  /// [16, 4096]); cache write failures are ignored (the table is still returned).
  static std::shared_ptr<const VisibilityTable> build(const Mesh& mesh, int subdivisions,
                                                      int resolution_px,
                                                      const std::string& cache_dir);

  /// File used by build() in `cache_dir`: "visibility_<hash>.bin", the hash (FNV-1a 64) taken
  /// over the mesh vertices, faces and the settings.
  static std::string cache_file_path(const Mesh& mesh, int subdivisions, int resolution_px,
                                     const std::string& cache_dir);

  /// S = S_u1 ∩ S_u2 ∩ S_u3 for the icosphere face (u1, u2, u3) crossed by the ray from the
  /// bounding-box centre towards the camera; `direction_to_camera_object` is that ray in the
  /// object frame (need not be normalized). `invisible` is resized to the face count; entry f
  /// is 1 when face f is in S.
  void invisible_faces(const Eigen::Vector3d& direction_to_camera_object,
                       std::vector<std::uint8_t>& invisible) const;

  /// Same set as a bitset (see Bits), for the icosphere face `icosphere_face` (an index into
  /// icosphere().faces(), e.g. from icosphere_face()). `invisible` is resized to words().
  void invisible_bits(int icosphere_face, Bits& invisible) const;

  /// Index into icosphere().faces() of the face crossed by the ray towards the camera
  /// (object frame). Cheap (~0.1 us): callers cache S per icosphere face with it.
  int icosphere_face(const Eigen::Vector3d& direction_to_camera_object) const {
    return icosphere_.face_containing(direction_to_camera_object);
  }
  /// The three icosphere vertex (viewpoint) indices of that face.
  Eigen::Vector3i viewpoints(const Eigen::Vector3d& direction_to_camera_object) const {
    return icosphere_.face_vertices_containing(direction_to_camera_object);
  }

  /// S_u of one viewpoint (icosphere vertex index), words() words.
  const std::uint64_t* invisible_from_viewpoint(int vertex) const {
    return bits_.data() + static_cast<std::size_t>(vertex) * words_;
  }
  /// True when face `face` is in S_u of viewpoint `vertex`.
  bool is_invisible_from_viewpoint(int vertex, int face) const {
    return (invisible_from_viewpoint(vertex)[face >> 6] >> (face & 63)) & 1u;
  }

  const Icosphere& icosphere() const { return icosphere_; }
  int face_count() const { return face_count_; }
  int viewpoint_count() const { return static_cast<int>(icosphere_.vertices().size()); }
  int resolution_px() const { return resolution_px_; }
  /// 64-bit words per viewpoint bitset: ceil(face_count / 64).
  std::size_t words() const { return words_; }
  /// The mesh's bounding-box centre (object frame, metres), the icosphere's centre.
  const Eigen::Vector3d& center_object() const { return center_object_; }
  /// True when build() read the table from the disk cache instead of rendering it.
  bool loaded_from_cache() const { return loaded_from_cache_; }
  /// All viewpoints' bitsets, viewpoint-major (viewpoint_count() * words() words).
  const Bits& raw_bits() const { return bits_; }

  /// A table in which every face is visible from every viewpoint (all S_u empty); build()
  /// fills a real one.
  VisibilityTable(int subdivisions, int resolution_px, int face_count,
                  const Eigen::Vector3d& center_object);

 private:
  bool read_cache(const std::string& path, std::uint64_t hash);
  void write_cache(const std::string& path, std::uint64_t hash) const;

  Icosphere icosphere_;
  int resolution_px_;
  int face_count_;
  std::size_t words_;
  Eigen::Vector3d center_object_;
  Bits bits_;
  bool loaded_from_cache_ = false;
};

}  // namespace kct
