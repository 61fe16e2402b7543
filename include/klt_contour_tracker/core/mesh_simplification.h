#pragma once
/// \file mesh_simplification.h
/// A coarser copy of the object's mesh for drawing silhouettes (ours; the paper renders the
/// full mesh). The colour search draws two dozen silhouettes a lost frame at a working size of
/// about 320 px: a 150k-face scan spends nearly all of that time on triangles smaller than a
/// pixel.

#include "klt_contour_tracker/core/mesh.h"

namespace kct {

/// `mesh` simplified as far as its surface stays within `max_error_m` (metres) of the original:
/// meshoptimizer's quadric edge collapse (meshopt_simplify), which keeps the topology (no holes
/// open, boundary edges stay boundary edges) and the faces' winding. The result has the used
/// vertices only, no texture or texture coordinates, and the same base colour. A mesh the
/// simplifier cannot reduce comes back with the same faces; max_error_m = 0 gives a copy of the
/// geometry. Throws std::invalid_argument for a negative or non-finite error or a face whose
/// vertex index is out of range.
Mesh simplified_mesh(const Mesh& mesh, double max_error_m);

}  // namespace kct
