#include "klt_contour_tracker/core/contour_extractor.h"

#include <cmath>
#include <stdexcept>
#include <string>

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
                                std::to_string(visibility_->face_count()) +
                                " faces, the mesh " + std::to_string(face_count));

  face_planes_.resize(face_count);
  std::vector<bool> degenerate(face_count);
  for (int f = 0; f < face_count; ++f) {
    const Eigen::Vector3i& face = mesh_->faces[f];
    const Eigen::Vector3d& a = mesh_->vertices[face[0]];
    const Eigen::Vector3d n =
        (mesh_->vertices[face[1]] - a).cross(mesh_->vertices[face[2]] - a);
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
  const double cos_alpha = std::cos(sharp_edge_angle_deg * M_PI / 180.0);
  edges_ = mesh_->shared_edges();
  edge_info_.reserve(edges_.size());
  for (const MeshEdge& e : edges_) {
    EdgeInfo info;
    info.p = e.v0;
    info.q = e.v1;
    info.face1 = e.face0;
    info.face2 = e.face1;
    info.usable = !degenerate[e.face0] && !degenerate[e.face1];
    info.sharp = info.usable &&
                 face_planes_[e.face0].normal.dot(face_planes_[e.face1].normal) < cos_alpha;
    edge_info_.push_back(info);
  }
  face_state_.resize(face_count);
}

void ContourExtractor::compute_face_states(const Pose& object_to_camera) const {
  const Eigen::Matrix3d r = object_to_camera.linear();
  const Eigen::Vector3d camera_object = -(r.transpose() * object_to_camera.translation());

  const std::uint64_t* invisible = nullptr;
  if (visibility_) {
    const int icosphere_face =
        visibility_->icosphere_face(camera_object - visibility_->center_object());
    if (icosphere_face != cached_icosphere_face_) {
      visibility_->invisible_bits(icosphere_face, cached_invisible_);
      cached_icosphere_face_ = icosphere_face;
    }
    invisible = cached_invisible_.data();
  }

  const int face_count = static_cast<int>(face_planes_.size());
  for (int f = 0; f < face_count; ++f) {
    const FacePlane& plane = face_planes_[f];
    // (v - c) . n < 0 with v on the face: the face's front side looks at the camera.
    const bool front = plane.normal.dot(camera_object) > plane.offset;
    const bool hidden = invisible && ((invisible[f >> 6] >> (f & 63)) & 1u);
    face_state_[f] = static_cast<std::uint8_t>((front ? kFront : 0) |
                                               (front && !hidden ? kFrontVisible : 0));
  }
}

void ContourExtractor::classify(const Pose& object_to_camera, std::vector<EdgeType>& types) const {
  compute_face_states(object_to_camera);
  types.resize(edge_info_.size());
  for (std::size_t i = 0; i < edge_info_.size(); ++i) {
    const EdgeInfo& e = edge_info_[i];
    const std::uint8_t s1 = face_state_[e.face1], s2 = face_state_[e.face2];
    EdgeType type = EdgeType::kOther;
    if (e.usable) {
      const bool front1 = s1 & kFront, front2 = s2 & kFront;
      const bool visible1 = s1 & kFrontVisible, visible2 = s2 & kFrontVisible;
      if ((visible1 && !front2) || (visible2 && !front1))
        type = EdgeType::kContour;
      else if (visible1 && visible2 && e.sharp)
        type = EdgeType::kSharp;
    }
    types[i] = type;
  }
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
  // Contour or Sharp and are classified per call.
  const Eigen::Vector3d center =
      visibility_ ? visibility_->center_object() : mesh_->bounding_box_center();
  candidate_camera_ = camera_object;
  candidate_radius_ = kCandidateRadiusFraction * (camera_object - center).norm();
  candidates_.clear();
  for (std::size_t i = 0; i < edge_info_.size(); ++i) {
    const EdgeInfo& e = edge_info_[i];
    if (!e.usable) continue;
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
  if (!(candidate_radius_ >= 0.0) || !((camera_object - candidate_camera_).norm() <= candidate_radius_))
    rebuild_candidates(camera_object);
  const std::uint64_t* invisible = nullptr;
  if (visibility_) {
    const int icosphere_face =
        visibility_->icosphere_face(camera_object - visibility_->center_object());
    if (icosphere_face != cached_icosphere_face_) {
      visibility_->invisible_bits(icosphere_face, cached_invisible_);
      cached_icosphere_face_ = icosphere_face;
    }
    invisible = cached_invisible_.data();
  }
  // Same test as compute_face_states(), for the candidates' faces only.
  auto state = [&](int f) {
    const FacePlane& plane = face_planes_[f];
    const bool front = plane.normal.dot(camera_object) > plane.offset;
    const bool hidden = invisible && ((invisible[f >> 6] >> (f & 63)) & 1u);
    return static_cast<std::uint8_t>((front ? kFront : 0) | (front && !hidden ? kFrontVisible : 0));
  };
  const std::vector<Eigen::Vector3d>& vertices = mesh_->vertices;
  for (const int i : candidates_) {  // ascending edge order, as a full classify()
    const EdgeInfo& e = edge_info_[i];
    const std::uint8_t s1 = state(e.face1), s2 = state(e.face2);
    const bool front1 = s1 & kFront, front2 = s2 & kFront;
    const bool visible1 = s1 & kFrontVisible, visible2 = s2 & kFrontVisible;
    EdgeType type = EdgeType::kOther;
    if ((visible1 && !front2) || (visible2 && !front1))
      type = EdgeType::kContour;
    else if (visible1 && visible2 && e.sharp)
      type = EdgeType::kSharp;
    if (type == EdgeType::kOther) continue;
    const Eigen::Vector3d a = r * vertices[e.p] + t;
    const Eigen::Vector3d b = r * vertices[e.q] + t;
    if (a.z() <= kMinDepth || b.z() <= kMinDepth) continue;
    segments.push_back({camera.project(a), camera.project(b), type, i});
  }
}

}  // namespace kct
