/// \file make_benchmark_models.cpp
/// Generates the benchmark's textured models (metres, z up, origin at the bounding-box centre),
/// spanning the OPT dataset's range of complexity (Sec. 4.2 of the paper: 2.6k to 176k faces):
///   can     (~2.3k faces)  a soda can: surface of revolution with bevels, rim and recessed top
///   chest   (~4k faces)    a box with a barrel lid, metal bands and a lock
///   rock    (~20k faces)   an organic, smoothly displaced and elongated icosphere
///   bike    (~150k faces)  a bicycle-like frame: two torus wheels with spokes, many tubes
///   toy     (~4.8k faces)    UNTEXTURED: a uniform-colour organic toy (a sitting bear-like figure
///                          of smooth blobs), shading only
///   castle  (18 faces)     UNTEXTURED and OPEN, like ViSP's castle CAD model: a floor polygon,
///                          a square tower of four walls and a front wall, no closing faces
/// Textures are crops of real photographs from the Debian package opencv-doc
/// (/usr/share/doc/opencv-doc/examples/data, OpenCV's sample data, BSD/Apache licensed), one
/// per axis direction (+x, -x, +y, -y, +z, -z), applied by a per-face planar (triplanar)
/// projection. Deterministic: the same OpenCV version and photographs give the same files.
///
/// Usage: make_benchmark_models [--output-dir DIR=data/benchmark/models] [--only NAME]
///                              [--photo-dir DIR=/usr/share/doc/opencv-doc/examples/data]

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "klt_contour_tracker/core/mesh.h"

namespace {

using Eigen::Vector3d;

/// Triangle soup made of closed parts; every part is re-oriented outward (positive volume).
struct Builder {
  std::vector<Vector3d> vertices;
  std::vector<std::array<int, 3>> faces;
  std::size_t part_start = 0;

  int add(const Vector3d& p) {
    vertices.push_back(p);
    return static_cast<int>(vertices.size()) - 1;
  }
  void tri(int a, int b, int c) { faces.push_back({a, b, c}); }
  void quad(int a, int b, int c, int d) { tri(a, b, c), tri(a, c, d); }
  void begin_part() { part_start = faces.size(); }
  /// Flips the faces of the current part when its signed volume is negative.
  void end_part() {
    Vector3d centroid = Vector3d::Zero();
    int n = 0;
    for (std::size_t f = part_start; f < faces.size(); ++f)
      for (int k : faces[f]) centroid += vertices[k], ++n;
    centroid /= std::max(n, 1);
    double volume = 0.0;
    for (std::size_t f = part_start; f < faces.size(); ++f) {
      const auto& t = faces[f];
      volume += (vertices[t[0]] - centroid)
                    .dot((vertices[t[1]] - centroid).cross(vertices[t[2]] - centroid));
    }
    if (volume < 0.0)
      for (std::size_t f = part_start; f < faces.size(); ++f) std::swap(faces[f][1], faces[f][2]);
  }
};

/// Rotation taking +z to `axis`.
Eigen::Matrix3d frame_for(const Vector3d& axis) {
  return Eigen::Quaterniond::FromTwoVectors(Vector3d::UnitZ(), axis.normalized()).toRotationMatrix();
}

/// Closed surface of revolution around +z of a profile (r, z) running from one pole (r = 0) to
/// the other, placed by (rotation, origin).
void revolve(Builder& b, const std::vector<Eigen::Vector2d>& profile, int segments,
             const Eigen::Matrix3d& rotation, const Vector3d& origin) {
  b.begin_part();
  std::vector<std::vector<int>> rings;
  for (const auto& p : profile) {
    std::vector<int> ring;
    if (p.x() <= 0.0) {
      ring.assign(segments, b.add(origin + rotation * Vector3d(0, 0, p.y())));
    } else {
      for (int s = 0; s < segments; ++s) {
        const double a = 2.0 * M_PI * s / segments;
        ring.push_back(b.add(origin + rotation * Vector3d(p.x() * std::cos(a), p.x() * std::sin(a), p.y())));
      }
    }
    rings.push_back(ring);
  }
  for (std::size_t i = 0; i + 1 < rings.size(); ++i)
    for (int s = 0; s < segments; ++s) {
      const int t = (s + 1) % segments;
      const int a = rings[i][s], c = rings[i][t], d = rings[i + 1][t], e = rings[i + 1][s];
      if (a != c) b.tri(a, c, d);
      if (d != e) b.tri(a, d, e);
    }
  b.end_part();
}

/// Capped cylinder (tube) from p0 to p1 with `rings` subdivisions along its length.
void tube(Builder& b, const Vector3d& p0, const Vector3d& p1, double radius, int segments, int rings) {
  const double length = (p1 - p0).norm();
  std::vector<Eigen::Vector2d> profile{{0.0, 0.0}};
  for (int i = 0; i <= rings; ++i) profile.emplace_back(radius, length * i / rings);
  profile.emplace_back(0.0, length);
  revolve(b, profile, segments, frame_for(p1 - p0), p0);
}

/// Torus around `axis` through `center`.
void torus(Builder& b, const Vector3d& center, const Vector3d& axis, double major, double minor,
           int major_segments, int minor_segments) {
  b.begin_part();
  const Eigen::Matrix3d r = frame_for(axis);
  const int first = static_cast<int>(b.vertices.size());
  for (int i = 0; i < major_segments; ++i) {
    const double u = 2.0 * M_PI * i / major_segments;
    for (int j = 0; j < minor_segments; ++j) {
      const double v = 2.0 * M_PI * j / minor_segments;
      const double rho = major + minor * std::cos(v);
      b.add(center + r * Vector3d(rho * std::cos(u), rho * std::sin(u), minor * std::sin(v)));
    }
  }
  auto id = [&](int i, int j) {
    return first + (i % major_segments) * minor_segments + (j % minor_segments);
  };
  for (int i = 0; i < major_segments; ++i)
    for (int j = 0; j < minor_segments; ++j) b.quad(id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
  b.end_part();
}

/// Prism: a convex polygon in the (y, z) plane (any winding) extruded from x0 to x1 with
/// `subdivisions` segments along x; caps are fans from the polygon's centroid.
void extrude_x(Builder& b, const std::vector<Eigen::Vector2d>& polygon, double x0, double x1,
               int subdivisions) {
  b.begin_part();
  const int n = static_cast<int>(polygon.size());
  std::vector<std::vector<int>> rings;
  for (int k = 0; k <= subdivisions; ++k) {
    const double x = x0 + (x1 - x0) * k / subdivisions;
    std::vector<int> ring;
    for (const auto& p : polygon) ring.push_back(b.add({x, p.x(), p.y()}));
    rings.push_back(ring);
  }
  for (int k = 0; k < subdivisions; ++k)
    for (int i = 0; i < n; ++i) b.quad(rings[k][i], rings[k + 1][i], rings[k + 1][(i + 1) % n], rings[k][(i + 1) % n]);
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const auto& p : polygon) centroid += p;
  centroid /= n;
  const int c0 = b.add({x0, centroid.x(), centroid.y()});
  const int c1 = b.add({x1, centroid.x(), centroid.y()});
  for (int i = 0; i < n; ++i) {
    b.tri(c0, rings[0][(i + 1) % n], rings[0][i]);
    b.tri(c1, rings[subdivisions][i], rings[subdivisions][(i + 1) % n]);
  }
  b.end_part();
}

/// Axis-aligned box with each face split into an n x n grid (vertices on shared edges are
/// duplicated; load_mesh merges them by position).
void box(Builder& b, const Vector3d& lo, const Vector3d& hi, int n) {
  b.begin_part();
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      std::vector<int> ids;
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j) {
          Vector3d p;
          p[axis] = side ? hi[axis] : lo[axis];
          p[u] = lo[u] + (hi[u] - lo[u]) * i / n;
          p[v] = lo[v] + (hi[v] - lo[v]) * j / n;
          ids.push_back(b.add(p));
        }
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const int a = ids[i * (n + 1) + j], c = ids[(i + 1) * (n + 1) + j];
          const int d = ids[(i + 1) * (n + 1) + j + 1], e = ids[i * (n + 1) + j + 1];
          if (side) b.quad(a, c, d, e);
          else b.quad(a, e, d, c);
        }
    }
  b.end_part();
}

/// Icosphere subdivided `levels` times (20 * 4^levels faces) with each unit direction d
/// mapped to radius_of(d) * d.
void displaced_sphere(Builder& b, int levels, const Vector3d& center,
                      const std::function<Vector3d(const Vector3d&)>& place) {
  b.begin_part();
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                             {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p.normalize();
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9},
                                       {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int c) {
      const auto key = std::minmax(a, c);
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      v.push_back((v[a] + v[c]).normalized());
      return midpoint[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& tr : f) {
      const int ab = mid(tr[0], tr[1]), bc = mid(tr[1], tr[2]), ca = mid(tr[2], tr[0]);
      next.push_back({tr[0], ab, ca});
      next.push_back({tr[1], bc, ab});
      next.push_back({tr[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    f.swap(next);
  }
  const int first = static_cast<int>(b.vertices.size());
  for (const auto& d : v) b.add(center + place(d));
  for (const auto& tr : f) b.tri(first + tr[0], first + tr[1], first + tr[2]);
  b.end_part();
}

void make_can(Builder& b) {
  // Profile (radius, height), bottom pole to top pole, metres: domed base, bevelled heel,
  // straight wall, tapered neck, rolled rim and a recessed lid.
  std::vector<Eigen::Vector2d> p = {{0.0, 0.006}, {0.020, 0.004}, {0.027, 0.001}, {0.030, 0.0},
                                    {0.0325, 0.003}, {0.033, 0.008}};
  for (int i = 1; i <= 8; ++i) p.emplace_back(0.033, 0.008 + 0.094 * i / 8);
  const std::vector<Eigen::Vector2d> top = {{0.0315, 0.108}, {0.0285, 0.113}, {0.0275, 0.1165},
                                            {0.0270, 0.1180}, {0.0255, 0.1175}, {0.0250, 0.1130},
                                            {0.0, 0.1125}};
  p.insert(p.end(), top.begin(), top.end());
  revolve(b, p, 64, Eigen::Matrix3d::Identity(), Vector3d::Zero());
  // Pull tab on the lid (a thin box), breaking the rotational symmetry of the shape.
  box(b, {-0.004, -0.018, 0.1125}, {0.004, 0.004, 0.1145}, 2);
}

void make_chest(Builder& b) {
  const double lx = 0.08, ly = 0.05, h = 0.08;  // half length, half depth, body height
  box(b, {-lx, -ly, 0.0}, {lx, ly, h}, 12);
  // Barrel lid: half-disc cross-section extruded along x.
  auto arc = [&](double radius, double squash, int segments) {
    std::vector<Eigen::Vector2d> poly;
    for (int i = 0; i <= segments; ++i) {
      const double a = M_PI * i / segments;
      poly.emplace_back(radius * std::cos(a), h + squash * radius * std::sin(a));
    }
    return poly;
  };
  extrude_x(b, arc(ly, 0.7, 48), -lx, lx, 16);
  for (double x : {-0.05, 0.05}) {
    extrude_x(b, arc(ly + 0.003, 0.7, 48), x - 0.006, x + 0.006, 2);  // lid bands
    box(b, {x - 0.006, -ly - 0.003, 0.0}, {x + 0.006, ly + 0.003, h}, 3);  // body bands
  }
  box(b, {-lx - 0.003, -ly - 0.003, 0.0}, {lx + 0.003, ly + 0.003, 0.008}, 6);  // plinth
  box(b, {-0.012, -ly - 0.008, h - 0.024}, {0.012, -ly + 0.001, h + 0.004}, 3);  // lock
}

void make_rock(Builder& b) {
  displaced_sphere(b, 5, Vector3d::Zero(), [](const Vector3d& d) {
    const double bump = 0.10 * std::sin(3.1 * d.x() + 0.4) * std::cos(2.3 * d.y() - 0.7) +
                        0.07 * std::sin(5.3 * d.z() + 1.9 * d.x()) +
                        0.04 * std::cos(9.7 * d.y() + 4.1 * d.z());
    const double r = 0.06 * (1.0 + bump);
    return Vector3d(1.35 * r * d.x(), r * d.y(), 0.9 * r * d.z());
  });
  // A knob and a ridge break the near-symmetry.
  displaced_sphere(b, 3, Vector3d(0.045, 0.03, 0.03),
                   [](const Vector3d& d) { return Vector3d(0.028 * d.x(), 0.02 * d.y(), 0.024 * d.z()); });
}

void make_toy(Builder& b) {
  auto ellipsoid = [&](int levels, const Vector3d& center, const Vector3d& radii, double wobble) {
    displaced_sphere(b, levels, center, [=](const Vector3d& d) {
      const double r = 1.0 + wobble * std::sin(4.0 * d.x() + 1.0) * std::cos(3.0 * d.y());
      return Vector3d(radii.x() * r * d.x(), radii.y() * r * d.y(), radii.z() * r * d.z());
    });
  };
  ellipsoid(3, {0.0, 0.0, 0.045}, {0.042, 0.036, 0.05}, 0.04);      // body
  ellipsoid(3, {0.0, -0.006, 0.115}, {0.032, 0.03, 0.03}, 0.02);   // head
  ellipsoid(2, {0.0, -0.035, 0.108}, {0.012, 0.012, 0.01}, 0.0);   // snout
  for (double s : {-1.0, 1.0}) {
    ellipsoid(2, {0.022 * s, -0.002, 0.142}, {0.01, 0.006, 0.01}, 0.0);   // ears
    ellipsoid(2, {0.045 * s, -0.01, 0.06}, {0.012, 0.013, 0.028}, 0.0);   // arms
    ellipsoid(2, {0.024 * s, -0.03, 0.01}, {0.015, 0.028, 0.013}, 0.0);   // legs
  }
}

/// Open low-poly CAD model: single-sided polygons only (floor, four tower walls without roof
/// or bottom, a front wall), the kind of mesh CAD exports and ViSP's .cao castle are.
void make_castle(Builder& b) {
  const double fx = 0.11, fy = 0.08;  // floor half extents
  b.quad(b.add({-fx, -fy, 0}), b.add({fx, -fy, 0}), b.add({fx, fy, 0}), b.add({-fx, fy, 0}));
  // Tower on the back-left of the floor: 4 walls, open top and bottom.
  const double x0 = -0.09, x1 = -0.03, y0 = 0.0, y1 = 0.06, h = 0.13;
  const Vector3d corners[4] = {{x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, {x0, y1, 0}};
  for (int k = 0; k < 4; ++k) {
    const Vector3d& p = corners[k];
    const Vector3d& q = corners[(k + 1) % 4];
    b.quad(b.add(p), b.add(q), b.add(q + Vector3d(0, 0, h)), b.add(p + Vector3d(0, 0, h)));
  }
  // Front wall with a gate: three quads around an opening.
  const double wy = -0.05, wh = 0.06, g0 = -0.015, g1 = 0.015, gh = 0.035;
  b.quad(b.add({-0.1, wy, 0}), b.add({g0, wy, 0}), b.add({g0, wy, wh}), b.add({-0.1, wy, wh}));
  b.quad(b.add({g1, wy, 0}), b.add({0.1, wy, 0}), b.add({0.1, wy, wh}), b.add({g1, wy, wh}));
  b.quad(b.add({g0, wy, gh}), b.add({g1, wy, gh}), b.add({g1, wy, wh}), b.add({g0, wy, wh}));
  // A slope (ramp) to the right of the tower.
  b.quad(b.add({0.02, 0.0, 0}), b.add({0.09, 0.0, 0}), b.add({0.09, 0.07, 0.05}), b.add({0.02, 0.07, 0.05}));
}

void make_bike(Builder& b) {
  const double R = 0.1, tyre = 0.011;
  const Vector3d rear(-0.17, 0.0, 0.0), front(0.17, 0.0, 0.0), axle = Vector3d::UnitY();
  for (const Vector3d& c : {rear, front}) {
    torus(b, c, axle, R, tyre, 192, 32);                   // tyre
    torus(b, c, axle, R - tyre - 0.004, 0.004, 192, 16);  // rim
    tube(b, c - Vector3d(0, 0.022, 0), c + Vector3d(0, 0.022, 0), 0.008, 32, 8);  // hub
    for (int s = 0; s < 24; ++s) {  // spokes, laced alternately to the hub flanges
      const double a = 2.0 * M_PI * s / 24;
      const Vector3d rim = c + (R - tyre - 0.006) * Vector3d(std::cos(a), 0, std::sin(a));
      const Vector3d hub = c + Vector3d(0.006 * std::cos(a), s % 2 ? 0.018 : -0.018, 0.006 * std::sin(a));
      tube(b, hub, rim, 0.0012, 8, 24);
    }
  }
  const Vector3d bottom(-0.02, 0.0, -0.01), seat_top(-0.07, 0.0, 0.16), head_low(0.12, 0.0, 0.11),
      head_top(0.105, 0.0, 0.16);
  const double r = 0.0075;
  auto frame_tube = [&](const Vector3d& p, const Vector3d& q, double radius) { tube(b, p, q, radius, 48, 72); };
  frame_tube(bottom, seat_top, r);                       // seat tube
  frame_tube(seat_top + Vector3d(0.01, 0, -0.01), head_top, r);  // top tube
  frame_tube(bottom, head_low, r * 1.15);                // down tube
  for (double y : {-0.02, 0.02}) {
    frame_tube(rear + Vector3d(0, y, 0), bottom + Vector3d(0, y * 0.5, 0), r * 0.6);  // chain stays
    frame_tube(rear + Vector3d(0, y, 0), seat_top + Vector3d(0.01, y * 0.3, -0.02), r * 0.6);  // seat stays
    frame_tube(front + Vector3d(0, y, 0), head_low + Vector3d(0, y * 0.6, 0), r * 0.7);  // fork
  }
  frame_tube(head_low - Vector3d(-0.005, 0, 0.02), head_top + Vector3d(-0.004, 0, 0.04), r * 1.3);  // head tube
  frame_tube(head_top + Vector3d(-0.01, -0.12, 0.05), head_top + Vector3d(-0.01, 0.12, 0.05), r * 0.9);  // handlebar
  frame_tube(seat_top, seat_top + Vector3d(-0.01, 0, 0.04), r * 0.8);  // seat post
  displaced_sphere(b, 4, seat_top + Vector3d(-0.005, 0, 0.05),
                   [](const Vector3d& d) { return Vector3d(0.05 * d.x(), 0.022 * d.y(), 0.012 * d.z()); });  // saddle
  torus(b, bottom + Vector3d(0, 0.03, 0), axle, 0.045, 0.003, 128, 12);  // chainring
  for (double s : {-1.0, 1.0}) {  // cranks and pedals
    const Vector3d end = bottom + Vector3d(0.05 * s, 0.045 * s, -0.03 * s);
    tube(b, bottom + Vector3d(0, 0.04 * s, 0), end, 0.004, 16, 8);
    box(b, end + Vector3d(-0.012, s > 0 ? 0.0 : -0.03, -0.005), end + Vector3d(0.012, s > 0 ? 0.03 : 0.0, 0.005), 4);
  }
}

/// 3 x 2 atlas of 512 px photo crops, one per axis direction; a face goes to the region of its
/// dominant normal direction and is projected orthographically onto that region.
struct Atlas {
  cv::Mat image;
  static constexpr int kTile = 512;

  Atlas(const std::string& photo_dir, const std::vector<std::string>& photos) {
    image = cv::Mat(2 * kTile, 3 * kTile, CV_8UC3, cv::Scalar(128, 128, 128));
    for (int i = 0; i < 6; ++i) {
      const std::string path = photo_dir + "/" + photos[i % photos.size()];
      cv::Mat photo = cv::imread(path, cv::IMREAD_COLOR);
      if (photo.empty()) throw std::runtime_error("cannot read photograph " + path + " (install opencv-doc)");
      const int side = std::min(photo.cols, photo.rows);
      // Alternate crops of a photograph when it is used twice.
      const int offset_x = (i / photos.size()) % 2 ? photo.cols - side : 0;
      cv::Mat tile;
      cv::resize(photo(cv::Rect(offset_x, (photo.rows - side) / 2, side, side)), tile,
                 cv::Size(kTile, kTile), 0, 0, cv::INTER_AREA);
      tile.copyTo(image(cv::Rect((i % 3) * kTile, (i / 3) * kTile, kTile, kTile)));
    }
  }
};

struct ModelSpec {
  std::string name;
  std::function<void(Builder&)> build;
  std::vector<std::string> photos;  ///< empty: untextured, uniform `color`
  std::string description;
  Vector3d color{0.8, 0.5, 0.2};    ///< RGB in [0, 1], untextured models only
};

/// Writes an untextured model: one material of uniform diffuse colour (Kd), no texture.
void write_untextured(const ModelSpec& spec, const Builder& b, const std::string& dir) {
  {
    std::ofstream mtl(dir + "/" + spec.name + ".mtl");
    mtl << "# " << spec.name << ": made by klt_contour_tracker's make_benchmark_models (BSD-3-Clause)\n"
        << "newmtl " << spec.name << "\nKa 1 1 1\nKd " << spec.color.x() << " " << spec.color.y()
        << " " << spec.color.z() << "\nKs 0 0 0\nillum 1\n";
    if (!mtl) throw std::runtime_error("cannot write the .mtl of " + spec.name);
  }
  const std::string obj_path = dir + "/" + spec.name + ".obj";
  std::ofstream obj(obj_path);
  obj << "# " << spec.name << ": " << spec.description
      << "\n# made by klt_contour_tracker's make_benchmark_models (BSD-3-Clause); metres, z up\n"
      << "mtllib " << spec.name << ".mtl\no " << spec.name << "\nusemtl " << spec.name << "\n";
  char line[128];
  for (const auto& p : b.vertices) {
    std::snprintf(line, sizeof(line), "v %.6f %.6f %.6f\n", p.x(), p.y(), p.z());
    obj << line;
  }
  for (const auto& t : b.faces) obj << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
  obj.close();
  if (!obj) throw std::runtime_error("cannot write " + obj_path);
  const kct::Mesh mesh = kct::load_mesh(obj_path);
  std::cout << spec.name << ": " << mesh.faces.size() << " faces, " << mesh.vertices.size()
            << " vertices, diameter " << mesh.diameter() << " m, untextured -> " << obj_path << "\n";
}

void write_model(const ModelSpec& spec, const std::string& dir, const std::string& photo_dir) {
  Builder b;
  spec.build(b);
  // Centre on the bounding box.
  Vector3d lo = b.vertices[0], hi = b.vertices[0];
  for (const auto& p : b.vertices) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Vector3d center = 0.5 * (lo + hi), extent = (hi - lo).cwiseMax(1e-9);
  for (auto& p : b.vertices) p -= center;
  lo -= center;

  if (spec.photos.empty()) {
    write_untextured(spec, b, dir);
    return;
  }
  const Atlas atlas(photo_dir, spec.photos);
  const std::string png = spec.name + ".png";
  if (!cv::imwrite(dir + "/" + png, atlas.image, {cv::IMWRITE_PNG_COMPRESSION, 6}))
    throw std::runtime_error("cannot write " + dir + "/" + png);
  {
    std::ofstream mtl(dir + "/" + spec.name + ".mtl");
    mtl << "# " << spec.name << ": made by klt_contour_tracker's make_benchmark_models (BSD-3-Clause);\n"
        << "# texture: crops of OpenCV sample photographs (Debian package opencv-doc)\n"
        << "newmtl " << spec.name << "\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd " << png << "\n";
    if (!mtl) throw std::runtime_error("cannot write the .mtl of " + spec.name);
  }
  const std::string obj_path = dir + "/" + spec.name + ".obj";
  std::ofstream obj(obj_path);
  obj << "# " << spec.name << ": " << spec.description
      << "\n# made by klt_contour_tracker's make_benchmark_models (BSD-3-Clause); metres, z up\n"
      << "mtllib " << spec.name << ".mtl\no " << spec.name << "\n";
  char line[128];
  for (const auto& p : b.vertices) {
    std::snprintf(line, sizeof(line), "v %.6f %.6f %.6f\n", p.x(), p.y(), p.z());
    obj << line;
  }
  // One texture coordinate per (vertex, region) pair.
  std::map<std::pair<int, int>, int> uv_ids;
  std::vector<std::array<int, 3>> face_uvs;
  for (const auto& t : b.faces) {
    const Vector3d n = (b.vertices[t[1]] - b.vertices[t[0]]).cross(b.vertices[t[2]] - b.vertices[t[0]]);
    int axis = 0;
    n.cwiseAbs().maxCoeff(&axis);
    const int region = 2 * axis + (n[axis] < 0 ? 1 : 0);
    const int u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
    std::array<int, 3> ids{};
    for (int k = 0; k < 3; ++k) {
      auto [it, inserted] = uv_ids.emplace(std::make_pair(t[k], region), static_cast<int>(uv_ids.size()) + 1);
      if (inserted) {
        const Vector3d& p = b.vertices[t[k]];
        const double s = 0.02 + 0.96 * (p[u_axis] - lo[u_axis]) / extent[u_axis];
        const double r = 0.02 + 0.96 * (p[v_axis] - lo[v_axis]) / extent[v_axis];
        const double px = ((region % 3) + s) * Atlas::kTile, py = ((region / 3) + 1.0 - r) * Atlas::kTile;
        std::snprintf(line, sizeof(line), "vt %.6f %.6f\n", px / atlas.image.cols, 1.0 - py / atlas.image.rows);
        obj << line;
      }
      ids[k] = it->second;
    }
    face_uvs.push_back(ids);
  }
  obj << "usemtl " << spec.name << "\n";
  for (std::size_t f = 0; f < b.faces.size(); ++f) {
    const auto& t = b.faces[f];
    std::snprintf(line, sizeof(line), "f %d/%d %d/%d %d/%d\n", t[0] + 1, face_uvs[f][0], t[1] + 1,
                  face_uvs[f][1], t[2] + 1, face_uvs[f][2]);
    obj << line;
  }
  obj.close();
  if (!obj) throw std::runtime_error("cannot write " + obj_path);
  const kct::Mesh mesh = kct::load_mesh(obj_path);
  std::cout << spec.name << ": " << mesh.faces.size() << " faces, " << mesh.vertices.size()
            << " vertices, diameter " << mesh.diameter() << " m -> " << obj_path << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::string output_dir = "data/benchmark/models", only,
              photo_dir = "/usr/share/doc/opencv-doc/examples/data";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h" || i + 1 >= argc) {
      std::cerr << "usage: make_benchmark_models [--output-dir DIR] [--only can|chest|rock|bike|toy|castle]"
                   " [--photo-dir DIR]\n";
      return arg == "--help" || arg == "-h" ? 0 : 2;
    }
    const std::string value = argv[++i];
    if (arg == "--output-dir") output_dir = value;
    else if (arg == "--only") only = value;
    else if (arg == "--photo-dir") photo_dir = value;
    else {
      std::cerr << "make_benchmark_models: unknown option " << arg << "\n";
      return 2;
    }
  }
  const std::vector<ModelSpec> specs = {
      {"can", make_can, {"fruits.jpg", "baboon.jpg", "orange.jpg", "smarties.png", "HappyFish.jpg", "apple.jpg"},
       "soda-can-like surface of revolution with a pull tab, 66 x 66 x 118 mm"},
      {"chest", make_chest, {"building.jpg", "board.jpg", "home.jpg", "stuff.jpg", "leuvenA.jpg", "aero1.jpg"},
       "chest with a barrel lid, bands, plinth and lock, 166 x 116 x 115 mm"},
      {"rock", make_rock, {"starry_night.jpg", "butterfly.jpg", "messi5.jpg", "squirrel_cls.jpg", "graf1.png", "pic1.png"},
       "organic displaced icosphere (level 5) with a knob, about 170 x 120 x 100 mm"},
      {"bike", make_bike, {"baboon.jpg", "fruits.jpg", "building.jpg", "starry_night.jpg", "smarties.png", "board.jpg"},
       "bicycle-like frame of many tubes, torus wheels with spokes, about 570 x 240 x 330 mm"},
      {"toy", make_toy, {}, "untextured uniform-colour toy figure of smooth blobs, about 110 x 90 x 150 mm",
       {0.85, 0.55, 0.15}},
      {"castle", make_castle, {}, "untextured OPEN low-poly castle: floor, tower walls, front wall, ramp, "
       "no closing faces, 220 x 160 x 130 mm", {0.75, 0.72, 0.65}},
  };
  try {
    std::filesystem::create_directories(output_dir);
    bool found = false;
    for (const auto& spec : specs)
      if (only.empty() || only == spec.name) write_model(spec, output_dir, photo_dir), found = true;
    if (!found) throw std::invalid_argument("no model named '" + only + "'");
  } catch (const std::exception& e) {
    std::cerr << "make_benchmark_models: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
