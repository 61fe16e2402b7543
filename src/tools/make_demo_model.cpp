/// \file make_demo_model.cpp
/// Generates the package's demo model models/demo_crate.{obj,mtl,png}: a 0.12 x 0.08 x 0.06 m
/// box with one chamfered vertical edge and an off-centre block on top (closed, 2-manifold,
/// metres, z up), textured with a procedural, corner-rich pattern. Deterministic for a seed.
///
/// Usage: make_demo_model [--output-dir DIR=models] [--seed N=7] [--texture-size PX=1024]

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "klt_contour_tracker/core/mesh.h"

namespace {

/// A planar piece of the surface with its own texture chart.
struct Chart {
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;  ///< CCW seen from outside
  Eigen::Vector3d normal;                     ///< outward
  std::vector<Eigen::Vector2d> plane;         ///< 2D coordinates in the face plane, metres
  cv::Rect2d atlas;                           ///< placement in the texture, pixels
};

/// Convex polygon given CCW from outside, fan-triangulated.
Chart polygon(const std::vector<Eigen::Vector3d>& points) {
  Chart chart;
  chart.points = points;
  for (int i = 1; i + 1 < static_cast<int>(points.size()); ++i) chart.triangles.push_back({0, i, i + 1});
  chart.normal = (points[1] - points[0]).cross(points[2] - points[0]).normalized();
  return chart;
}

/// Prism side walls between a footprint polygon (CCW seen from +z) at z0 and z1.
std::vector<Chart> walls(const std::vector<Eigen::Vector2d>& footprint, double z0, double z1) {
  std::vector<Chart> charts;
  for (std::size_t i = 0; i < footprint.size(); ++i) {
    const Eigen::Vector2d& a = footprint[i];
    const Eigen::Vector2d& b = footprint[(i + 1) % footprint.size()];
    charts.push_back(polygon({{a.x(), a.y(), z0}, {b.x(), b.y(), z0}, {b.x(), b.y(), z1},
                              {a.x(), a.y(), z1}}));
  }
  return charts;
}

Eigen::Vector3d at_height(const Eigen::Vector2d& p, double z) { return {p.x(), p.y(), z}; }

/// In-plane basis (e1, e2) with e1 x e2 = normal, e1 horizontal on walls (texture upright).
void plane_coordinates(Chart& chart) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d e1 = std::abs(chart.normal.z()) > 0.9 ? Eigen::Vector3d::UnitX()
                                                        : up.cross(chart.normal).normalized();
  const Eigen::Vector3d e2 = chart.normal.cross(e1);
  chart.plane.clear();
  for (const auto& p : chart.points) chart.plane.emplace_back(p.dot(e1), p.dot(e2));
}

/// Shelf packing of the charts into a square texture at a common scale (pixels per metre),
/// the largest scale that fits. Returns the scale.
double pack(std::vector<Chart>& charts, int size_px, int padding_px) {
  for (double scale = 20000.0; scale > 100.0; scale *= 0.97) {
    std::vector<int> order(charts.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
    auto extent = [&](const Chart& c) {
      Eigen::Vector2d lo = c.plane[0], hi = c.plane[0];
      for (const auto& p : c.plane) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
      return Eigen::Vector2d((hi - lo) * scale);
    };
    std::sort(order.begin(), order.end(),
              [&](int a, int b) { return extent(charts[a]).y() > extent(charts[b]).y(); });
    double x = padding_px, y = padding_px, shelf_height = 0.0;
    bool fits = true;
    for (int i : order) {
      const Eigen::Vector2d e = extent(charts[i]);
      if (x + e.x() + padding_px > size_px) {
        x = padding_px;
        y += shelf_height + padding_px;
        shelf_height = 0.0;
      }
      if (x + e.x() + padding_px > size_px || y + e.y() + padding_px > size_px) {
        fits = false;
        break;
      }
      charts[i].atlas = cv::Rect2d(x, y, e.x(), e.y());
      x += e.x() + padding_px;
      shelf_height = std::max(shelf_height, e.y());
    }
    if (fits) return scale;
  }
  throw std::runtime_error("texture too small for the charts");
}

/// Colourful, high-frequency, corner-rich pattern: rectangles, rotated boxes, disks, stripes,
/// letters. Flat colours keep the PNG small.
cv::Mat make_texture(int size_px, uint64_t seed, const std::vector<Chart>& charts) {
  cv::RNG rng(seed);
  cv::Mat texture(size_px, size_px, CV_8UC3, cv::Scalar(60, 160, 230));
  auto color = [&] {
    return cv::Scalar(rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0, 256));
  };
  const double s = size_px / 1024.0;
  for (int i = 0; i < 160; ++i) {
    const cv::Point p(rng.uniform(0, size_px), rng.uniform(0, size_px));
    const cv::Size half(static_cast<int>(rng.uniform(8.0, 70.0) * s),
                        static_cast<int>(rng.uniform(8.0, 70.0) * s));
    cv::rectangle(texture, p - cv::Point(half.width, half.height),
                  p + cv::Point(half.width, half.height), color(), cv::FILLED);
  }
  for (int i = 0; i < 60; ++i) {
    const cv::RotatedRect box(cv::Point2f(rng.uniform(0.f, float(size_px)), rng.uniform(0.f, float(size_px))),
                              cv::Size2f(rng.uniform(15.f, 80.f) * s, rng.uniform(10.f, 50.f) * s),
                              rng.uniform(0.f, 180.f));
    cv::Point2f corners[4];
    box.points(corners);
    std::vector<cv::Point> poly(corners, corners + 4);
    cv::fillConvexPoly(texture, poly, color(), cv::LINE_8);
  }
  for (int i = 0; i < 70; ++i)
    cv::circle(texture, cv::Point(rng.uniform(0, size_px), rng.uniform(0, size_px)),
               static_cast<int>(rng.uniform(5.0, 35.0) * s), color(), cv::FILLED, cv::LINE_8);
  for (int i = 0; i < 40; ++i)
    cv::line(texture, cv::Point(rng.uniform(0, size_px), rng.uniform(0, size_px)),
             cv::Point(rng.uniform(0, size_px), rng.uniform(0, size_px)), color(),
             std::max(1, static_cast<int>(rng.uniform(2.0, 7.0) * s)), cv::LINE_8);
  const std::string letters = "KLTCONTOUR0123456789XYZ#@&";
  for (int i = 0; i < 90; ++i) {
    const std::string text(1, letters[rng.uniform(0, static_cast<int>(letters.size()))]);
    cv::putText(texture, text, cv::Point(rng.uniform(0, size_px), rng.uniform(0, size_px)),
                cv::FONT_HERSHEY_DUPLEX, rng.uniform(0.8, 2.2) * s, color(),
                std::max(1, static_cast<int>(3 * s)), cv::LINE_AA);
  }
  // A large label per chart makes every side distinguishable (no symmetric ambiguity).
  for (std::size_t i = 0; i < charts.size(); ++i) {
    const cv::Rect2d& r = charts[i].atlas;
    const std::string label(1, static_cast<char>('A' + i));
    const double font = std::min(r.width, r.height) / 45.0;
    cv::putText(texture, label, cv::Point(int(r.x + 0.3 * r.width), int(r.y + 0.75 * r.height)),
                cv::FONT_HERSHEY_SIMPLEX, font, cv::Scalar(20, 20, 20),
                std::max(2, static_cast<int>(font * 3)), cv::LINE_8);
  }
  return texture;
}

}  // namespace

int run(int argc, char** argv) {
  std::string output_dir = "models";
  uint64_t seed = 7;
  int texture_size = 1024;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument("missing value after " + arg);
      return argv[++i];
    };
    if (arg == "--output-dir") output_dir = next();
    else if (arg == "--seed") seed = std::stoull(next());
    else if (arg == "--texture-size") texture_size = std::stoi(next());
    else {
      std::cerr << "usage: make_demo_model [--output-dir DIR] [--seed N] [--texture-size PX]\n";
      return arg == "--help" || arg == "-h" ? 0 : 2;
    }
  }

  // Body footprint (CCW from +z) with the (+x, +y) vertical edge chamfered; block on top.
  const double z0 = -0.03, z1 = 0.03, z2 = 0.055;
  const std::vector<Eigen::Vector2d> body = {
      {-0.06, -0.04}, {0.06, -0.04}, {0.06, 0.02}, {0.04, 0.04}, {-0.06, 0.04}};
  const std::vector<Eigen::Vector2d> block = {
      {-0.05, -0.03}, {-0.01, -0.03}, {-0.01, 0.01}, {-0.05, 0.01}};

  std::vector<Chart> charts;
  {
    std::vector<Eigen::Vector3d> bottom;
    for (auto it = body.rbegin(); it != body.rend(); ++it) bottom.push_back(at_height(*it, z0));
    charts.push_back(polygon(bottom));
  }
  for (auto& wall : walls(body, z0, z1)) charts.push_back(wall);
  {  // Top of the body: the footprint ring around the block (points O0..O4 then I0..I3).
    Chart ring;
    for (const auto& p : body) ring.points.push_back(at_height(p, z1));
    for (const auto& p : block) ring.points.push_back(at_height(p, z1));
    ring.triangles = {{0, 1, 6}, {0, 6, 5}, {6, 1, 2}, {6, 2, 7}, {7, 2, 3},
                      {7, 3, 4}, {7, 4, 8}, {8, 4, 0}, {8, 0, 5}};
    ring.normal = Eigen::Vector3d::UnitZ();
    charts.push_back(ring);
  }
  for (auto& wall : walls(block, z1, z2)) charts.push_back(wall);
  {
    std::vector<Eigen::Vector3d> top;
    for (const auto& p : block) top.push_back(at_height(p, z2));
    charts.push_back(polygon(top));
  }

  for (auto& chart : charts) {
    plane_coordinates(chart);
    for (const auto& t : chart.triangles) {
      const Eigen::Vector3d n = (chart.points[t[1]] - chart.points[t[0]])
                                    .cross(chart.points[t[2]] - chart.points[t[0]]);
      if (n.dot(chart.normal) <= 0.0) throw std::logic_error("a triangle is not CCW from outside");
    }
  }
  const double pixels_per_metre = pack(charts, texture_size, 8);
  const cv::Mat texture = make_texture(texture_size, seed, charts);

  std::filesystem::create_directories(output_dir);
  const std::string obj_path = output_dir + "/demo_crate.obj";
  const std::string mtl_path = output_dir + "/demo_crate.mtl";
  const std::string png_path = output_dir + "/demo_crate.png";
  if (!cv::imwrite(png_path, texture, {cv::IMWRITE_PNG_COMPRESSION, 9}))
    throw std::runtime_error("cannot write " + png_path);
  {
    std::ofstream mtl(mtl_path);
    mtl << "# demo_crate: made by klt_contour_tracker's make_demo_model (BSD-3-Clause)\n"
        << "newmtl crate\nKa 1 1 1\nKd 1 1 1\nKs 0 0 0\nillum 1\nmap_Kd demo_crate.png\n";
    if (!mtl) throw std::runtime_error("cannot write " + mtl_path);
  }
  std::ofstream obj(obj_path);
  obj << "# demo_crate: made by klt_contour_tracker's make_demo_model --seed " << seed
      << " (BSD-3-Clause)\n# metres, z up; 0.12 x 0.08 x 0.06 m body with a chamfered edge and "
         "a block on top\nmtllib demo_crate.mtl\no demo_crate\n";
  std::map<std::array<long, 3>, int> vertex_ids;  // positions are exact multiples of 0.5 mm
  std::vector<std::vector<int>> chart_vertices(charts.size());
  for (std::size_t c = 0; c < charts.size(); ++c)
    for (const auto& p : charts[c].points) {
      const std::array<long, 3> key{std::lround(p.x() * 2e4), std::lround(p.y() * 2e4),
                                    std::lround(p.z() * 2e4)};
      auto it = vertex_ids.find(key);
      if (it == vertex_ids.end()) {
        it = vertex_ids.emplace(key, static_cast<int>(vertex_ids.size()) + 1).first;
        char line[96];
        std::snprintf(line, sizeof(line), "v %.6f %.6f %.6f\n", p.x(), p.y(), p.z());
        obj << line;
      }
      chart_vertices[c].push_back(it->second);
    }
  int vt_count = 0;
  std::vector<int> chart_vt_start(charts.size());
  for (std::size_t c = 0; c < charts.size(); ++c) {
    const Chart& chart = charts[c];
    Eigen::Vector2d lo = chart.plane[0], hi = chart.plane[0];
    for (const auto& p : chart.plane) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    chart_vt_start[c] = vt_count + 1;
    for (const auto& p : chart.plane) {
      const double px = chart.atlas.x + (p.x() - lo.x()) * pixels_per_metre;
      const double py = chart.atlas.y + (hi.y() - p.y()) * pixels_per_metre;
      char line[64];
      std::snprintf(line, sizeof(line), "vt %.6f %.6f\n", px / texture_size,
                    1.0 - py / texture_size);
      obj << line;
      ++vt_count;
    }
  }
  obj << "usemtl crate\n";
  int face_count = 0;
  for (std::size_t c = 0; c < charts.size(); ++c)
    for (const auto& t : charts[c].triangles) {
      obj << "f";
      for (int k : t) obj << ' ' << chart_vertices[c][k] << '/' << chart_vt_start[c] + k;
      obj << '\n';
      ++face_count;
    }
  obj.close();
  if (!obj) throw std::runtime_error("cannot write " + obj_path);

  const kct::Mesh mesh = kct::load_mesh(obj_path);
  const std::size_t edges = mesh.shared_edges().size();
  std::cout << "wrote " << obj_path << ": " << mesh.vertices.size() << " vertices, "
            << mesh.faces.size() << " faces, " << edges << " shared edges ("
            << (edges * 2 == mesh.faces.size() * 3 ? "closed" : "NOT closed") << "), diameter "
            << mesh.diameter() << " m, texture " << texture_size << " px at "
            << pixels_per_metre / 1000.0 << " px/mm\n";
  return edges * 2 == mesh.faces.size() * 3 ? 0 : 1;
}

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "make_demo_model: " << e.what() << "\n";
    return 1;
  }
}
