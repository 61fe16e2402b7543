#include "klt_contour_tracker/core/icosphere.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace kct {
namespace {

Eigen::Matrix3d edge_planes_of(const std::vector<Eigen::Vector3d>& v, const Eigen::Vector3i& f) {
  Eigen::Matrix3d planes;
  planes.row(0) = v[f[0]].cross(v[f[1]]).normalized().transpose();
  planes.row(1) = v[f[1]].cross(v[f[2]]).normalized().transpose();
  planes.row(2) = v[f[2]].cross(v[f[0]]).normalized().transpose();
  return planes;
}

/// Smallest signed distance (sine of the angle) of `d` to the face's three edge planes:
/// >= 0 inside the spherical triangle.
inline double inside_score(const Eigen::Matrix3d& planes, const Eigen::Vector3d& d) {
  const Eigen::Vector3d s = planes * d;
  return s.minCoeff();
}

}  // namespace

Icosphere::Icosphere(int subdivisions) : subdivisions_(subdivisions) {
  if (subdivisions < 0 || subdivisions > 7)
    throw std::invalid_argument("Icosphere: subdivisions must be in [0, 7], got " +
                                std::to_string(subdivisions));
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  const double base[12][3] = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                              {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                              {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  const int base_faces[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (const auto& p : base) vertices_.push_back(Eigen::Vector3d(p[0], p[1], p[2]).normalized());

  levels_.resize(subdivisions + 1);
  for (const auto& f : base_faces) {
    Eigen::Vector3i face(f[0], f[1], f[2]);
    const Eigen::Vector3d &a = vertices_[face[0]], &b = vertices_[face[1]],
                          &c = vertices_[face[2]];
    if ((b - a).cross(c - a).dot(a) < 0.0) std::swap(face[1], face[2]);  // CCW from outside
    levels_[0].faces.push_back(face);
  }

  for (int level = 1; level <= subdivisions; ++level) {
    std::unordered_map<std::uint64_t, int> midpoints;
    auto midpoint = [&](int i, int j) {
      const std::uint64_t key = (static_cast<std::uint64_t>(std::min(i, j)) << 32) |
                                static_cast<std::uint32_t>(std::max(i, j));
      const auto found = midpoints.find(key);
      if (found != midpoints.end()) return found->second;
      vertices_.push_back((vertices_[i] + vertices_[j]).normalized());
      const int index = static_cast<int>(vertices_.size()) - 1;
      midpoints.emplace(key, index);
      return index;
    };
    const std::vector<Eigen::Vector3i>& parents = levels_[level - 1].faces;
    std::vector<Eigen::Vector3i>& children = levels_[level].faces;
    children.reserve(parents.size() * 4);
    for (const Eigen::Vector3i& f : parents) {
      const int ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]), ca = midpoint(f[2], f[0]);
      children.emplace_back(f[0], ab, ca);
      children.emplace_back(f[1], bc, ab);
      children.emplace_back(f[2], ca, bc);
      children.emplace_back(ab, bc, ca);
    }
  }

  for (Level& level : levels_) {
    level.edge_planes.reserve(level.faces.size());
    for (const Eigen::Vector3i& f : level.faces)
      level.edge_planes.push_back(edge_planes_of(vertices_, f));
  }
}

int Icosphere::face_containing(const Eigen::Vector3d& direction) const {
  if (!direction.allFinite() || direction.squaredNorm() == 0.0) return 0;
  // Scores are not normalized by |direction|: only their order matters.
  int best = 0;
  double best_score = -std::numeric_limits<double>::infinity();
  for (int f = 0; f < static_cast<int>(levels_[0].faces.size()); ++f) {
    const double score = inside_score(levels_[0].edge_planes[f], direction);
    if (score > best_score) best_score = score, best = f;
  }
  for (std::size_t level = 1; level < levels_.size(); ++level) {
    const int first_child = 4 * best;
    best_score = -std::numeric_limits<double>::infinity();
    for (int child = first_child; child < first_child + 4; ++child) {
      const double score = inside_score(levels_[level].edge_planes[child], direction);
      if (score > best_score) best_score = score, best = child;
    }
  }
  return best;
}

}  // namespace kct
