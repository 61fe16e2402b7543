#pragma once
// Synthetic scenes for the core tests: a textured box, a noisy background, and rendered
// frames at known poses. Everything is made here, so the tests need no file outside the repo.

#include <memory>
#include <opencv2/imgproc.hpp>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"
#include "klt_contour_tracker/core/renderer.h"

namespace kct {
namespace test {

/// Corner-rich random texture (seeded): rectangles and disks of random grey levels.
inline cv::Mat make_texture(int size_px, int seed) {
  cv::RNG rng(seed);
  cv::Mat texture(size_px, size_px, CV_8UC3, cv::Scalar(128, 128, 128));
  for (int i = 0; i < 400; ++i) {
    const cv::Scalar colour(rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0, 256));
    const cv::Point p(rng.uniform(0, size_px), rng.uniform(0, size_px));
    if (i % 2)
      cv::rectangle(texture, p, p + cv::Point(rng.uniform(4, 30), rng.uniform(4, 30)), colour, -1);
    else
      cv::circle(texture, p, rng.uniform(3, 15), colour, -1);
  }
  return texture;
}

/// Axis-aligned box centred at the origin with the given sizes in metres, 12 CCW triangles,
/// 8 shared vertices, each face mapped to its own cell of a 3x2 texture atlas.
inline Mesh make_box(double sx, double sy, double sz, bool textured = true, int seed = 7) {
  Mesh mesh;
  const double x = sx / 2, y = sy / 2, z = sz / 2;
  mesh.vertices = {{-x, -y, -z}, {x, -y, -z}, {x, y, -z}, {-x, y, -z},
                   {-x, -y, z},  {x, -y, z},  {x, y, z},  {-x, y, z}};
  // Each quad (a, b, c, d) is CCW seen from outside.
  const int quads[6][4] = {{4, 5, 6, 7}, {1, 0, 3, 2}, {5, 1, 2, 6},
                           {0, 4, 7, 3}, {7, 6, 2, 3}, {0, 1, 5, 4}};
  for (int q = 0; q < 6; ++q) {
    const int* v = quads[q];
    mesh.faces.emplace_back(v[0], v[1], v[2]);
    mesh.faces.emplace_back(v[0], v[2], v[3]);
    const float u0 = (q % 3) / 3.0f, v0 = (q / 3) / 2.0f, du = 1 / 3.0f, dv = 0.5f;
    const Eigen::Vector2f a(u0, v0), b(u0 + du, v0), c(u0 + du, v0 + dv), d(u0, v0 + dv);
    mesh.corner_uvs.insert(mesh.corner_uvs.end(), {a, b, c, a, c, d});
  }
  if (textured) mesh.texture = make_texture(384, seed);
  else mesh.corner_uvs.clear();
  return mesh;
}

/// Appends the axis-aligned box [lo, hi]: 8 vertices, 12 triangles wound counter-clockwise
/// from outside (quad order -z, +z, -y, +y, -x, +x; two triangles each), 18 shared edges.
inline void append_box(Mesh& mesh, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const int base = static_cast<int>(mesh.vertices.size());
  for (int i = 0; i < 8; ++i)
    mesh.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(),
                               i & 4 ? hi.z() : lo.z());
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  const Eigen::Vector3d center = 0.5 * (lo + hi);
  for (const auto& q : quads)
    for (const auto& tri : {Eigen::Vector3i(q[0], q[1], q[2]), Eigen::Vector3i(q[0], q[2], q[3])}) {
      Eigen::Vector3i f = tri.array() + base;
      const auto &a = mesh.vertices[f[0]], &b = mesh.vertices[f[1]], &c = mesh.vertices[f[2]];
      if ((b - a).cross(c - a).dot(a - center) < 0.0) std::swap(f[1], f[2]);
      mesh.faces.push_back(f);
    }
}

/// Axis-aligned cube of side `side_m` centred at the origin (append_box()), untextured.
inline std::shared_ptr<Mesh> make_cube(double side_m) {
  auto mesh = std::make_shared<Mesh>();
  append_box(*mesh, Eigen::Vector3d::Constant(-0.5 * side_m), Eigen::Vector3d::Constant(0.5 * side_m));
  return mesh;
}

/// Smooth random colour background (seeded): uniform noise on a grid of `cell_px` cells with
/// values in [low, high), upsampled bicubically. Small cells and a wide range make clutter.
inline cv::Mat make_background(const cv::Size& size, int seed, int cell_px = 16, int low = 40,
                               int high = 200) {
  cv::RNG rng(seed);
  cv::Mat small(size.height / cell_px + 1, size.width / cell_px + 1, CV_8UC3);
  rng.fill(small, cv::RNG::UNIFORM, low, high);
  cv::Mat background;
  cv::resize(small, background, size, 0, 0, cv::INTER_CUBIC);
  return background;
}

/// The mesh rendered at `object_to_camera` over `background`, plus Gaussian noise.
inline cv::Mat render_frame(const Renderer& renderer, const PinholeCamera& camera,
                            const Pose& object_to_camera, const cv::Mat& background,
                            double noise_sigma = 2.0, int seed = 3,
                            const RenderOptions& options = {}) {
  const RenderOutput out = renderer.render(object_to_camera, camera, options);
  cv::Mat frame = background.clone();
  out.color.copyTo(frame, out.mask());
  if (noise_sigma > 0) {
    cv::Mat noise(frame.size(), CV_16SC3);
    cv::RNG rng(seed);
    rng.fill(noise, cv::RNG::NORMAL, 0, noise_sigma);
    cv::Mat frame16;
    frame.convertTo(frame16, CV_16SC3);
    frame16 += noise;
    frame16.convertTo(frame, CV_8UC3);
  }
  return frame;
}

inline PinholeCamera make_camera() { return PinholeCamera(600, 600, 319.5, 239.5, 640, 480); }

/// A pose looking at the object from `distance_m` with a generic orientation.
inline Pose make_pose(double distance_m, double rx_deg = 25, double ry_deg = -35, double rz_deg = 10) {
  Pose pose = Pose::Identity();
  pose.linear() = (Eigen::AngleAxisd(rz_deg * M_PI / 180, Eigen::Vector3d::UnitZ()) *
                   Eigen::AngleAxisd(ry_deg * M_PI / 180, Eigen::Vector3d::UnitY()) *
                   Eigen::AngleAxisd(rx_deg * M_PI / 180, Eigen::Vector3d::UnitX()))
                      .toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.01, -0.005, distance_m);
  return pose;
}

/// `pose` moved by a small camera-frame motion (degrees about an axis through the object
/// origin, then a translation in metres).
inline Pose move(const Pose& pose, double angle_deg, const Eigen::Vector3d& axis,
                 const Eigen::Vector3d& translation_m) {
  Pose moved = pose;
  moved.linear() = Eigen::AngleAxisd(angle_deg * M_PI / 180, axis.normalized()) * pose.linear();
  moved.translation() += translation_m;
  return moved;
}

}  // namespace test
}  // namespace kct
