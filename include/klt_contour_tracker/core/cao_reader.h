#pragma once
/// \file cao_reader.h
/// Reader for ViSP's `.cao` CAD model format (the model file of visp_tracker and
/// vpMbGenericTracker), so that a ViSP user's model loads without conversion.

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace kct {

/// A `.cao` model as polygons over points, in the file's units (ViSP uses metres) and the
/// file's object frame. Polygons are counter-clockwise seen from outside (ViSP's convention:
/// their normal (p1 - p0) x (p2 - p0) points out of the object).
struct CaoModel {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::vector<int>> polygons;  ///< indices into `points`, >= 3 each
};

/// Parses a `.cao` file. Supported, as ViSP reads them:
/// - an optional `V1` header line; `#` starts a comment anywhere; LF or CRLF line endings;
/// - `load("other.cao")` lines before the points (path relative to the including file's
///   folder; each file has its own point indices; nesting up to 16 deep, cycles rejected);
/// - the sections in order: points (`x y z`), 3D lines (`i j`), faces from lines
///   (`n l0 .. l(n-1)`, the lines chained into a closed loop), faces from points
///   (`n p0 .. p(n-1)`), cylinders (`i j radius`) and circles (`radius centre p1 p2`); trailing
///   `key=value` options (`name=`, `useLod=` ...) and other trailing tokens are ignored, as
///   ViSP does; the cylinder and circle sections may be absent.
/// Lines that are not part of a face carry no surface and are ignored. Cylinders and circles
/// are triangulated (ViSP tracks them as analytic primitives; here they become facets):
/// a cylinder becomes an open tube of `curve_segments` side quads between the planes through
/// its two axis points (no caps, as ViSP models caps with circles), normals outward; a circle
/// becomes a flat polygon of `curve_segments` corners, its normal (p1 - centre) x (p2 - centre).
/// Throws std::runtime_error naming the file, the line number and what was expected.
CaoModel read_cao(const std::string& path, int curve_segments = 32);

/// Triangles (index triples into `points`) covering a planar polygon given by indices into
/// `points`, wound as the polygon, by ear clipping in the polygon's plane (concave polygons
/// included; a self-intersecting outline ends as a fan).
std::vector<std::array<int, 3>> triangulate_polygon(const std::vector<Eigen::Vector3d>& points,
                                                    const std::vector<int>& polygon);

/// The model as Wavefront OBJ text: one `v` line per point, its polygons as triangles
/// (triangulate_polygon()), so that load_mesh() reads it through assimp like any mesh file.
std::string cao_to_obj(const CaoModel& model);

}  // namespace kct
