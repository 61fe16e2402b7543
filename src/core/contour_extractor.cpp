#include "klt_contour_tracker/core/contour_extractor.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace kct {
namespace {

constexpr std::uint8_t kFront = 1;
constexpr std::uint8_t kFrontVisible = 2;
constexpr double kMinDepth = 1e-6;  // metres
// Candidate edges are re-selected when the camera centre (object frame) moved by more than
// this fraction of its distance to the object's centre (about 6 deg of rotation).
constexpr double kCandidateRadiusFraction = 0.1;

}  // namespace

ContourExtractor::ContourExtractor(std::shared_ptr<const Mesh> mesh,
                                   std::shared_ptr<const VisibilityTable> visibility,
                                   double sharp_edge_angle_deg)
    : mesh_(std::move(mesh)),
      visibility_(std::move(visibility)),
      sharp_edge_angle_deg_(sharp_edge_angle_deg) {
  if (!mesh_) throw std::invalid_argument("ContourExtractor: mesh is null");
  if (!(sharp_edge_angle_deg >= 0.0 && sharp_edge_angle_deg <= 180.0))
    throw std::invalid_argument("ContourExtractor: sharp_edge_angle_deg must be in [0, 180], got " +
                                std::to_string(sharp_edge_angle_deg));
  const int face_count = static_cast<int>(mesh_->faces.size());
  if (visibility_ && visibility_->face_count() != face_count)
    throw std::invalid_argument("ContourExtractor: visibility table has " +
                                std::to_string(visibility_->face_count()) + " faces, the mesh " +
                                std::to_string(face_count));

  face_planes_.resize(face_count);
  std::vector<bool> degenerate(face_count);
  for (int f = 0; f < face_count; ++f) {
    const Eigen::Vector3i& face = mesh_->faces[f];
    const Eigen::Vector3d& a = mesh_->vertices[face[0]];
    const Eigen::Vector3d n = (mesh_->vertices[face[1]] - a).cross(mesh_->vertices[face[2]] - a);
    const double length = n.norm();
    degenerate[f] = !(length > 0.0) || !std::isfinite(length);
    face_planes_[f].normal = degenerate[f] ? Eigen::Vector3d::Zero() : Eigen::Vector3d(n / length);
    face_planes_[f].offset = face_planes_[f].normal.dot(a);
  }

  // Sharp-edge criterion. The paper's Algorithm 1 prints "pi - arccos(|n1 . n2|) > alpha",
  // which is a typo: for coplanar faces it gives pi > alpha, marking every flat edge sharp.
  // Implemented is the evident intent of Sec. 3.5 ("faces meet at an angle no greater than
  // alpha", i.e. the dihedral angle is at most pi - alpha): the angle between the two unit
  // face normals exceeds alpha, n1 . n2 < cos(alpha). A cube's edges (90 deg) are sharp for
  // alpha = 45 deg, a finely tessellated cylinder's side edges are not.
  cos_alpha_ = std::cos(sharp_edge_angle_deg * M_PI / 180.0);

  // Every edge with its faces: (vertex pair, face) entries sorted by pair. Two-face edges are
  // listed first (the order of Mesh::shared_edges(), so closed meshes are unchanged), then
  // boundary and non-manifold edges.
  std::vector<std::pair<std::uint64_t, int>> entries;
  entries.reserve(mesh_->faces.size() * 3);
  for (int f = 0; f < face_count; ++f)
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::uint32_t>(mesh_->faces[f][k]);
      const auto b = static_cast<std::uint32_t>(mesh_->faces[f][(k + 1) % 3]);
      if (a == b) continue;
      entries.emplace_back((static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b), f);
    }
  std::sort(entries.begin(), entries.end());
  std::vector<EdgeInfo> others;
  std::vector<MeshEdge> other_edges;
  std::vector<int> faces;
  for (std::size_t i = 0; i < entries.size();) {
    std::size_t j = i;
    faces.clear();
    for (; j < entries.size() && entries[j].first == entries[i].first; ++j)
      if (faces.empty() || faces.back() != entries[j].second) faces.push_back(entries[j].second);
    EdgeInfo info;
    info.p = static_cast<int>(entries[i].first >> 32);
    info.q = static_cast<int>(entries[i].first & 0xffffffffu);
    i = j;
    if (faces.size() == 2) {
      info.face1 = faces[0];
      info.face2 = faces[1];
      info.usable = !degenerate[faces[0]] && !degenerate[faces[1]];
      info.sharp = info.usable &&
                   face_planes_[faces[0]].normal.dot(face_planes_[faces[1]].normal) < cos_alpha_;
      edge_info_.push_back(info);
      edges_.push_back({info.p, info.q, faces[0], faces[1]});
      continue;
    }
    if (faces.size() == 1) {
      info.face1 = faces[0];
      info.face2 = -1;
      info.usable = !degenerate[faces[0]];
      info.sharp = false;
    } else {
      info.face1 = info.face2 = -1;
      info.sharp = false;
      info.extra_begin = static_cast<int>(extra_faces_.size());
      for (int f : faces)
        if (!degenerate[f]) extra_faces_.push_back(f);
      info.extra_end = static_cast<int>(extra_faces_.size());
      info.usable = info.extra_end > info.extra_begin;
    }
    others.push_back(info);
    other_edges.push_back({info.p, info.q, faces[0], faces.size() > 1 ? faces[1] : -1});
  }
  edge_info_.insert(edge_info_.end(), others.begin(), others.end());
  edges_.insert(edges_.end(), other_edges.begin(), other_edges.end());
  face_state_.resize(face_count);
}

void ContourExtractor::compute_face_states(const Pose& object_to_camera) const {
  const Eigen::Matrix3d r = object_to_camera.linear();
  const Eigen::Vector3d camera_object = -(r.transpose() * object_to_camera.translation());

  const std::uint64_t* invisible = invisible_bits(camera_object);
  const int face_count = static_cast<int>(face_planes_.size());
  for (int f = 0; f < face_count; ++f) face_state_[f] = face_state(f, camera_object, invisible);
}

const std::uint64_t* ContourExtractor::invisible_bits(const Eigen::Vector3d& camera_object) const {
  if (!visibility_) return nullptr;
  const int icosphere_face =
      visibility_->icosphere_face(camera_object - visibility_->center_object());
  if (icosphere_face != cached_icosphere_face_) {
    visibility_->invisible_bits(icosphere_face, cached_invisible_);
    cached_icosphere_face_ = icosphere_face;
  }
  return cached_invisible_.data();
}

std::uint8_t ContourExtractor::face_state(int f, const Eigen::Vector3d& camera_object,
                                          const std::uint64_t* invisible) const {
  const FacePlane& plane = face_planes_[f];
  // (v - c) . n < 0 with v on the face: the face's front side looks at the camera.
  const bool front = plane.normal.dot(camera_object) > plane.offset;
  const bool hidden = invisible && ((invisible[f >> 6] >> (f & 63)) & 1u);
  return static_cast<std::uint8_t>((front ? kFront : 0) | (front && !hidden ? kFrontVisible : 0));
}

template <typename State>
EdgeType ContourExtractor::edge_type(const EdgeInfo& e, const State& state) const {
  if (!e.usable) return EdgeType::kOther;
  if (e.face2 >= 0) {  // Algorithm 1
    const std::uint8_t s1 = state(e.face1), s2 = state(e.face2);
    const bool front1 = s1 & kFront, front2 = s2 & kFront;
    const bool visible1 = s1 & kFrontVisible, visible2 = s2 & kFrontVisible;
    if ((visible1 && !front2) || (visible2 && !front1)) return EdgeType::kContour;
    if (visible1 && visible2 && e.sharp) return EdgeType::kSharp;
    return EdgeType::kOther;
  }
  if (e.face1 >= 0)  // boundary edge: an outline wherever its face is seen
    return (state(e.face1) & kFrontVisible) ? EdgeType::kContour : EdgeType::kOther;
  // Non-manifold edge: the two-face rule applied to any pair of its faces.
  bool any_visible = false, any_back = false;
  for (int k = e.extra_begin; k < e.extra_end; ++k) {
    const std::uint8_t s = state(extra_faces_[k]);
    any_visible = any_visible || (s & kFrontVisible);
    any_back = any_back || !(s & kFront);
  }
  if (!any_visible) return EdgeType::kOther;
  if (any_back) return EdgeType::kContour;
  for (int k = e.extra_begin; k < e.extra_end; ++k) {
    if (!(state(extra_faces_[k]) & kFrontVisible)) continue;
    for (int m = k + 1; m < e.extra_end; ++m)
      if ((state(extra_faces_[m]) & kFrontVisible) &&
          face_planes_[extra_faces_[k]].normal.dot(face_planes_[extra_faces_[m]].normal) <
              cos_alpha_)
        return EdgeType::kSharp;
  }
  return EdgeType::kOther;
}

void ContourExtractor::classify(const Pose& object_to_camera, std::vector<EdgeType>& types) const {
  compute_face_states(object_to_camera);
  types.resize(edge_info_.size());
  const auto state = [this](int f) { return face_state_[f]; };
  for (std::size_t i = 0; i < edge_info_.size(); ++i) types[i] = edge_type(edge_info_[i], state);
}

std::vector<ContourSegment> ContourExtractor::extract(const Pose& object_to_camera,
                                                      const PinholeCamera& camera) const {
  std::vector<ContourSegment> segments;
  extract(object_to_camera, camera, segments);
  return segments;
}

void ContourExtractor::rebuild_candidates(const Eigen::Vector3d& camera_object) const {
  // Within |c - c_ref| <= R every face's signed distance n . c - n . v changes by at most R
  // (|n| = 1), so a face farther than R from the camera centre keeps its side. An edge whose
  // two faces both keep their side is kOther for every such c when both are back-facing, or
  // both front-facing and the edge is not sharp (Algorithm 1); only the other edges can be
  // Contour or Sharp and are classified per call. Boundary and non-manifold edges (few) are
  // always candidates.
  const Eigen::Vector3d center =
      visibility_ ? visibility_->center_object() : mesh_->bounding_box_center();
  candidate_camera_ = camera_object;
  candidate_radius_ = kCandidateRadiusFraction * (camera_object - center).norm();
  candidates_.clear();
  for (std::size_t i = 0; i < edge_info_.size(); ++i) {
    const EdgeInfo& e = edge_info_[i];
    if (!e.usable) continue;
    if (e.face2 < 0) {
      candidates_.push_back(static_cast<int>(i));
      continue;
    }
    const FacePlane& p1 = face_planes_[e.face1];
    const FacePlane& p2 = face_planes_[e.face2];
    const double s1 = p1.normal.dot(camera_object) - p1.offset;
    const double s2 = p2.normal.dot(camera_object) - p2.offset;
    const bool near = std::abs(s1) <= candidate_radius_ || std::abs(s2) <= candidate_radius_;
    const bool front1 = s1 > 0.0, front2 = s2 > 0.0;
    if (near || front1 != front2 || (front1 && front2 && e.sharp))
      candidates_.push_back(static_cast<int>(i));
  }
}

void ContourExtractor::extract(const Pose& object_to_camera, const PinholeCamera& camera,
                               std::vector<ContourSegment>& segments) const {
  segments.clear();
  const Eigen::Matrix3d r = object_to_camera.linear();
  const Eigen::Vector3d t = object_to_camera.translation();
  const Eigen::Vector3d camera_object = -(r.transpose() * t);
  if (!(candidate_radius_ >= 0.0) ||
      !((camera_object - candidate_camera_).norm() <= candidate_radius_))
    rebuild_candidates(camera_object);
  const std::uint64_t* invisible = invisible_bits(camera_object);
  // As compute_face_states(), for the candidates' faces only.
  const auto state = [&](int f) { return face_state(f, camera_object, invisible); };
  const std::vector<Eigen::Vector3d>& vertices = mesh_->vertices;
  for (const int i : candidates_) {  // ascending edge order, as a full classify()
    const EdgeInfo& e = edge_info_[i];
    const EdgeType type = edge_type(e, state);
    if (type == EdgeType::kOther) continue;
    const Eigen::Vector3d a = r * vertices[e.p] + t;
    const Eigen::Vector3d b = r * vertices[e.q] + t;
    if (a.z() <= kMinDepth || b.z() <= kMinDepth) continue;
    segments.push_back({camera.project(a), camera.project(b), type, i});
  }
}

}  // namespace kct
