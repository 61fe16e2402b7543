#include "klt_contour_tracker/core/mesh_simplification.h"

#include <meshoptimizer.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace kct {

// Quadric-error edge collapse is a few hundred lines of careful code (error quadrics, collapse
// ordering, topology and flip checks); meshoptimizer, a Debian package, does it for a 150k-face
// mesh in about 40 ms on this project's machine.
Mesh simplified_mesh(const Mesh& mesh, double max_error_m) {
  if (!std::isfinite(max_error_m) || max_error_m < 0.0)
    throw std::invalid_argument("simplified_mesh: max_error_m must be finite and >= 0, got " +
                                std::to_string(max_error_m));
  const int vertex_count = static_cast<int>(mesh.vertices.size());
  std::vector<unsigned int> indices;
  indices.reserve(3 * mesh.faces.size());
  for (const Eigen::Vector3i& face : mesh.faces)
    for (int k = 0; k < 3; ++k) {
      if (face[k] < 0 || face[k] >= vertex_count)
        throw std::invalid_argument("simplified_mesh: vertex index " + std::to_string(face[k]) +
                                    " out of range [0, " + std::to_string(vertex_count) + ")");
      indices.push_back(static_cast<unsigned int>(face[k]));
    }

  std::vector<unsigned int> kept = indices;
  if (max_error_m > 0.0 && !indices.empty()) {
    std::vector<float> positions;
    positions.reserve(3 * mesh.vertices.size());
    for (const Eigen::Vector3d& v : mesh.vertices)
      for (int k = 0; k < 3; ++k) positions.push_back(static_cast<float>(v[k]));
    const std::size_t stride = 3 * sizeof(float);
    // meshopt_simplify's error is relative to the mesh's extent.
    const float scale = meshopt_simplifyScale(positions.data(), mesh.vertices.size(), stride);
    if (scale > 0.0f) {
      std::vector<unsigned int> out(indices.size());
      const std::size_t count = meshopt_simplify(
          out.data(), indices.data(), indices.size(), positions.data(), mesh.vertices.size(),
          stride, /*target_index_count=*/0, static_cast<float>(max_error_m / scale),
          /*options=*/0, /*result_error=*/nullptr);
      if (count >= 3) kept.assign(out.begin(), out.begin() + count);
    }
  }

  // Only the vertices the kept faces use, in their original order.
  Mesh result;
  result.base_color = mesh.base_color;
  std::vector<bool> used(mesh.vertices.size(), false);
  for (unsigned int i : kept) used[i] = true;
  std::vector<int> new_index(mesh.vertices.size(), -1);
  for (int i = 0; i < vertex_count; ++i)
    if (used[i]) {
      new_index[i] = static_cast<int>(result.vertices.size());
      result.vertices.push_back(mesh.vertices[i]);
    }
  result.faces.reserve(kept.size() / 3);
  for (std::size_t f = 0; f + 2 < kept.size(); f += 3)
    result.faces.emplace_back(new_index[kept[f]], new_index[kept[f + 1]], new_index[kept[f + 2]]);
  return result;
}

}  // namespace kct
