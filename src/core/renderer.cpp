#include "klt_contour_tracker/core/renderer.h"

#include "klt_contour_tracker/core/shadow_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace kct {
namespace {

/// Faces closer to the camera than this (metres) are clipped away.
constexpr double kNearPlane = 1e-3;

/// A triangle corner after projection: pixel coordinates (centre of pixel (u, v) at integer
/// (u, v)), the depth key that is interpolated linearly in screen space (1/z for perspective,
/// -z for orthographic: larger = closer), and the texture coordinates divided by z.
struct ScreenVertex {
  double x, y;
  double key;
  double u_key, v_key;  ///< u * key, v * key (perspective-correct interpolation)
};

/// Camera-frame corner with its texture coordinates, for near-plane clipping.
struct ClipVertex {
  Eigen::Vector3d p;
  Eigen::Vector2d uv;
};

/// Per-pixel buffers the rasterizer writes.
struct Buffers {
  cv::Mat key;         ///< CV_32F depth key, larger = closer
  cv::Mat face_index;  ///< CV_32S
  cv::Mat uv;          ///< CV_32FC2 interpolated texture coordinates (optional)
  /// CV_8U; when set, only the covered pixels are marked (255) and key, face_index and uv are
  /// not used: no depth test, and a pixel already covered is not tested again.
  cv::Mat silhouette;
};

/// Edge function of a -> b evaluated at p (twice the signed area of a, b, p).
inline double edge(const ScreenVertex& a, const ScreenVertex& b, double px, double py) {
  return (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x);
}

/// edge() with the end points taken in a fixed order, so that (a, b) and (b, a) give exactly
/// opposite values: two triangles sharing an edge then agree bit for bit on which side of it a
/// pixel centre lies, and no pixel along the edge is left to neither (no cracks).
inline double shared_edge(const ScreenVertex& a, const ScreenVertex& b, double px, double py) {
  if (a.x < b.x || (a.x == b.x && a.y < b.y)) return edge(a, b, px, py);
  return -edge(b, a, px, py);
}

/// Top-left fill rule for the orientation with positive area: pixels exactly on a top or left
/// edge belong to the triangle, on a bottom or right edge to its neighbour, so shared edges
/// are drawn once and the covered area equals the geometric area.
inline bool is_top_left(const ScreenVertex& a, const ScreenVertex& b) {
  const double dx = b.x - a.x, dy = b.y - a.y;
  return dy < 0.0 || (dy == 0.0 && dx > 0.0);
}

/// Rasterizes one triangle into the buffers with a z-buffer test on the depth key.
void rasterize(ScreenVertex v0, ScreenVertex v1, ScreenVertex v2, int face, Buffers& buffers) {
  double area = edge(v0, v1, v2.x, v2.y);
  if (!(std::abs(area) > 0.0)) return;  // degenerate or NaN
  if (area < 0.0) {                      // two-sided: bring both windings to one orientation
    std::swap(v1, v2);
    area = -area;
  }
  const bool silhouette_only = !buffers.silhouette.empty();
  const cv::Size size = silhouette_only ? buffers.silhouette.size() : buffers.key.size();
  const int width = size.width, height = size.height;
  const int x_min = std::max(0, static_cast<int>(std::ceil(std::min({v0.x, v1.x, v2.x}))));
  const int x_max =
      std::min(width - 1, static_cast<int>(std::floor(std::max({v0.x, v1.x, v2.x}))));
  const int y_min = std::max(0, static_cast<int>(std::ceil(std::min({v0.y, v1.y, v2.y}))));
  const int y_max =
      std::min(height - 1, static_cast<int>(std::floor(std::max({v0.y, v1.y, v2.y}))));
  if (x_min > x_max || y_min > y_max) return;

  const bool tl0 = is_top_left(v1, v2), tl1 = is_top_left(v2, v0), tl2 = is_top_left(v0, v1);
  const double inv_area = 1.0 / area;
  const bool write_uv = !buffers.uv.empty();

  if (silhouette_only) {
    // The same coverage test as below (a covered pixel's depth key is always > 0 in front of
    // the near plane), so the mask is the z-buffered render's.
    for (int y = y_min; y <= y_max; ++y) {
      uchar* row = buffers.silhouette.ptr<uchar>(y);
      for (int x = x_min; x <= x_max; ++x) {
        if (row[x]) continue;
        const double e0 = shared_edge(v1, v2, x, y), e1 = shared_edge(v2, v0, x, y),
                     e2 = shared_edge(v0, v1, x, y);
        if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) continue;
        if ((e0 == 0.0 && !tl0) || (e1 == 0.0 && !tl1) || (e2 == 0.0 && !tl2)) continue;
        row[x] = 255;
      }
    }
    return;
  }
  for (int y = y_min; y <= y_max; ++y) {
    float* key_row = buffers.key.ptr<float>(y);
    int* face_row = buffers.face_index.ptr<int>(y);
    for (int x = x_min; x <= x_max; ++x) {
      // Evaluated per pixel, not stepped incrementally: stepping accumulates rounding that
      // differs between the two triangles of a shared edge.
      const double e0 = shared_edge(v1, v2, x, y), e1 = shared_edge(v2, v0, x, y),
                   e2 = shared_edge(v0, v1, x, y);
      if (e0 < 0.0 || e1 < 0.0 || e2 < 0.0) continue;
      if ((e0 == 0.0 && !tl0) || (e1 == 0.0 && !tl1) || (e2 == 0.0 && !tl2)) continue;
      const double w0 = e0 * inv_area, w1 = e1 * inv_area, w2 = e2 * inv_area;
      const double key = w0 * v0.key + w1 * v1.key + w2 * v2.key;
      if (!(key > key_row[x])) continue;
      key_row[x] = static_cast<float>(key);
      face_row[x] = face;
      if (write_uv) {
        const double u = (w0 * v0.u_key + w1 * v1.u_key + w2 * v2.u_key) / key;
        const double v = (w0 * v0.v_key + w1 * v1.v_key + w2 * v2.v_key) / key;
        buffers.uv.at<cv::Vec2f>(y, x) = cv::Vec2f(static_cast<float>(u), static_cast<float>(v));
      }
    }
  }
}

/// Clips a camera-frame triangle against z = kNearPlane (Sutherland-Hodgman); returns the
/// polygon in front of the plane (0, 3 or 4 corners).
int clip_near(const ClipVertex in[3], ClipVertex out[4]) {
  int count = 0;
  for (int i = 0; i < 3; ++i) {
    const ClipVertex& a = in[i];
    const ClipVertex& b = in[(i + 1) % 3];
    const bool a_in = a.p.z() > kNearPlane, b_in = b.p.z() > kNearPlane;
    if (a_in) out[count++] = a;
    if (a_in != b_in) {
      const double t = (kNearPlane - a.p.z()) / (b.p.z() - a.p.z());
      out[count++] = {a.p + t * (b.p - a.p), a.uv + t * (b.uv - a.uv)};
    }
  }
  return count;
}

/// Bilinear texture lookup with repeat wrapping; (u, v) in OpenGL convention (v up).
/// Hand-written rather than cv::remap: only object pixels are sampled, and UVs outside
/// [0, 1] must wrap, which remap's border modes do not give for arbitrary coordinates.
cv::Vec3f sample_texture(const cv::Mat& texture, float u, float v) {
  const int w = texture.cols, h = texture.rows;
  const float x = u * w - 0.5f, y = (1.0f - v) * h - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float ax = x - fx, ay = y - fy;
  auto wrap = [](int i, int n) { return ((i % n) + n) % n; };
  const int x0 = wrap(static_cast<int>(fx), w), x1 = wrap(static_cast<int>(fx) + 1, w);
  const int y0 = wrap(static_cast<int>(fy), h), y1 = wrap(static_cast<int>(fy) + 1, h);
  const cv::Vec3b* r0 = texture.ptr<cv::Vec3b>(y0);
  const cv::Vec3b* r1 = texture.ptr<cv::Vec3b>(y1);
  cv::Vec3f out;
  for (int c = 0; c < 3; ++c)
    out[c] = (1 - ay) * ((1 - ax) * r0[x0][c] + ax * r0[x1][c]) +
             ay * ((1 - ax) * r1[x0][c] + ax * r1[x1][c]);
  return out;
}

/// Transforms the mesh to the camera frame (`points`), clips its faces at the near plane and
/// rasterizes them into `buffers` (both sides; `textured`: with the corners' UVs).
void draw_faces(const Mesh& mesh, const Pose& object_to_camera, const PinholeCamera& camera,
                bool textured, Buffers& buffers, std::vector<Eigen::Vector3d>& points) {
  points.resize(mesh.vertices.size());
  for (std::size_t i = 0; i < points.size(); ++i) points[i] = object_to_camera * mesh.vertices[i];

  auto to_screen = [&](const Eigen::Vector3d& p, const Eigen::Vector2d& uv) {
    const double inv_z = 1.0 / p.z();
    return ScreenVertex{camera.fx() * p.x() * inv_z + camera.cx(),
                        camera.fy() * p.y() * inv_z + camera.cy(), inv_z, uv.x() * inv_z,
                        uv.y() * inv_z};
  };

  for (int f = 0; f < static_cast<int>(mesh.faces.size()); ++f) {
    const Eigen::Vector3i& face = mesh.faces[f];
    ClipVertex corners[3];
    bool all_in_front = true, all_behind = true;
    for (int k = 0; k < 3; ++k) {
      corners[k].p = points[face[k]];
      corners[k].uv = textured ? mesh.corner_uvs[3 * f + k].cast<double>() : Eigen::Vector2d(0, 0);
      all_in_front = all_in_front && corners[k].p.z() > kNearPlane;
      all_behind = all_behind && corners[k].p.z() <= kNearPlane;
    }
    if (all_behind) continue;
    if (all_in_front) {
      rasterize(to_screen(corners[0].p, corners[0].uv), to_screen(corners[1].p, corners[1].uv),
                to_screen(corners[2].p, corners[2].uv), f, buffers);
      continue;
    }
    ClipVertex polygon[4];
    const int count = clip_near(corners, polygon);
    for (int k = 1; k + 1 < count; ++k)
      rasterize(to_screen(polygon[0].p, polygon[0].uv), to_screen(polygon[k].p, polygon[k].uv),
                to_screen(polygon[k + 1].p, polygon[k + 1].uv), f, buffers);
  }
}

}  // namespace

void Renderer::shade_per_pixel(const Pose& object_to_camera, const PinholeCamera& camera,
                               const RenderOptions& options,
                               const std::vector<Eigen::Vector3d>& points_camera,
                               const cv::Mat& uv, RenderOutput& out) const {
  const Mesh& mesh = *mesh_;
  const bool textured = !uv.empty();
  const Eigen::Matrix3d rotation = object_to_camera.linear();
  std::vector<Eigen::Vector3d> face_normals(mesh.faces.size());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    face_normals[f] = rotation * mesh.face_normal(static_cast<int>(f));
  std::vector<Eigen::Vector3d> vertex_normals;
  if (options.smooth_shading) {
    // Area-weighted: the unnormalized cross product of a face is twice its area times its normal.
    vertex_normals.assign(mesh.vertices.size(), Eigen::Vector3d::Zero());
    for (const auto& face : mesh.faces) {
      const Eigen::Vector3d n = (points_camera[face[1]] - points_camera[face[0]])
                                    .cross(points_camera[face[2]] - points_camera[face[0]]);
      for (int k = 0; k < 3; ++k) vertex_normals[face[k]] += n;
    }
    for (auto& n : vertex_normals) {
      const double length = n.norm();
      if (length > 0.0) n /= length;
    }
  }
  const Eigen::Vector3d light = options.light_direction_camera.normalized();
  const cv::Vec3f base(mesh.base_color[0], mesh.base_color[1], mesh.base_color[2]);
  out.color = cv::Mat(out.depth.size(), CV_8UC3, cv::Scalar(0, 0, 0));
  for (int y = 0; y < out.depth.rows; ++y) {
    const int* face_row = out.face_index.ptr<int>(y);
    const float* depth_row = out.depth.ptr<float>(y);
    cv::Vec3b* color_row = out.color.ptr<cv::Vec3b>(y);
    for (int x = 0; x < out.depth.cols; ++x) {
      const int f = face_row[x];
      if (f < 0) continue;
      const Eigen::Vector3d p = camera.back_project(Eigen::Vector2d(x, y)) * depth_row[x];
      Eigen::Vector3d n = face_normals[f];
      if (options.smooth_shading) {
        // Barycentric coordinates of p in the camera-frame triangle.
        const Eigen::Vector3i& face = mesh.faces[f];
        const Eigen::Vector3d a = points_camera[face[0]];
        const Eigen::Vector3d e1 = points_camera[face[1]] - a, e2 = points_camera[face[2]] - a,
                              d = p - a;
        const double d11 = e1.dot(e1), d12 = e1.dot(e2), d22 = e2.dot(e2);
        const double d1 = d.dot(e1), d2 = d.dot(e2), det = d11 * d22 - d12 * d12;
        if (det > 0.0) {
          const double b1 = std::clamp((d22 * d1 - d12 * d2) / det, 0.0, 1.0);
          const double b2 = std::clamp((d11 * d2 - d12 * d1) / det, 0.0, 1.0 - b1);
          const Eigen::Vector3d smooth = (1.0 - b1 - b2) * vertex_normals[face[0]] +
                                         b1 * vertex_normals[face[1]] + b2 * vertex_normals[face[2]];
          // Keep the face's side: an interpolated normal never points across the face plane.
          if (smooth.dot(n) > 0.0) n = smooth.normalized();
          else if (smooth.dot(n) < 0.0) n = -smooth.normalized();
        }
      }
      const Eigen::Vector3d to_eye = -p.normalized();
      if (n.dot(to_eye) < 0.0) n = -n;  // two-sided: the side seen by the camera
      const double lit = options.shadow_map ? options.shadow_map->lit_fraction(p) : 1.0;
      const double n_dot_l = std::max(0.0, n.dot(light));
      double highlight = 0.0;
      if (n_dot_l > 0.0 && options.specular > 0.0) {
        const Eigen::Vector3d half = (light + to_eye).normalized();
        highlight = options.specular * std::pow(std::max(0.0, n.dot(half)), options.shininess);
      }
      cv::Vec3f albedo = base;
      if (textured) {
        const cv::Vec2f t = uv.at<cv::Vec2f>(y, x);
        albedo = sample_texture(mesh.texture, t[0], t[1]);
      }
      const double s = options.light_gain * (options.ambient + lit * options.diffuse * n_dot_l);
      const double white = options.light_gain * lit * highlight * 255.0;
      color_row[x] = cv::Vec3b(cv::saturate_cast<uchar>(albedo[0] * s + white),
                               cv::saturate_cast<uchar>(albedo[1] * s + white),
                               cv::saturate_cast<uchar>(albedo[2] * s + white));
    }
  }
}

Renderer::Renderer(std::shared_ptr<const Mesh> mesh) : mesh_(std::move(mesh)) {
  if (!mesh_) throw std::invalid_argument("Renderer: mesh must not be null");
}

cv::Mat Renderer::render_silhouette(const Pose& object_to_camera,
                                    const PinholeCamera& camera) const {
  Buffers buffers;
  buffers.silhouette = cv::Mat(camera.height(), camera.width(), CV_8UC1, cv::Scalar(0));
  std::vector<Eigen::Vector3d> points;
  draw_faces(*mesh_, object_to_camera, camera, false, buffers, points);
  return buffers.silhouette;
}

RenderOutput Renderer::render(const Pose& object_to_camera, const PinholeCamera& camera,
                              const RenderOptions& options) const {
  const Mesh& mesh = *mesh_;
  const int width = camera.width(), height = camera.height();
  const bool textured = options.draw_color && mesh.has_texture();

  Buffers buffers;
  buffers.key = cv::Mat(height, width, CV_32F, cv::Scalar(0.0f));  // key = 1/z > 0 on faces
  buffers.face_index = cv::Mat(height, width, CV_32S, cv::Scalar(-1));
  if (textured) buffers.uv = cv::Mat(height, width, CV_32FC2, cv::Scalar(0.0f, 0.0f));

  std::vector<Eigen::Vector3d> points;
  draw_faces(mesh, object_to_camera, camera, textured, buffers, points);

  RenderOutput out;
  out.face_index = buffers.face_index;
  out.depth = cv::Mat(height, width, CV_32F, cv::Scalar(0.0f));
  for (int y = 0; y < height; ++y) {
    const float* key = buffers.key.ptr<float>(y);
    float* depth = out.depth.ptr<float>(y);
    for (int x = 0; x < width; ++x)
      if (key[x] > 0.0f) depth[x] = 1.0f / key[x];
  }
  if (!options.draw_color) return out;
  if (options.specular > 0.0 || options.smooth_shading || options.shadow_map) {
    shade_per_pixel(object_to_camera, camera, options, points, buffers.uv, out);
    return out;
  }

  // Flat Lambertian shading per face, two-sided (|n.l|) so inner faces seen through an
  // opening are lit too.
  const Eigen::Vector3d light = options.light_direction_camera.normalized();
  const Eigen::Matrix3d rotation = object_to_camera.linear();
  std::vector<float> intensity(mesh.faces.size());
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const Eigen::Vector3d n = rotation * mesh.face_normal(static_cast<int>(f));
    intensity[f] = static_cast<float>(
        options.light_gain * (options.ambient + options.diffuse * std::abs(n.dot(light))));
  }
  out.color = cv::Mat(height, width, CV_8UC3, cv::Scalar(0, 0, 0));
  const cv::Vec3f base(mesh.base_color[0], mesh.base_color[1], mesh.base_color[2]);
  for (int y = 0; y < height; ++y) {
    const int* face_row = out.face_index.ptr<int>(y);
    cv::Vec3b* color_row = out.color.ptr<cv::Vec3b>(y);
    for (int x = 0; x < width; ++x) {
      const int f = face_row[x];
      if (f < 0) continue;
      cv::Vec3f albedo = base;
      if (textured) {
        const cv::Vec2f uv = buffers.uv.at<cv::Vec2f>(y, x);
        albedo = sample_texture(mesh.texture, uv[0], uv[1]);
      }
      const float s = intensity[f];
      color_row[x] = cv::Vec3b(cv::saturate_cast<uchar>(albedo[0] * s),
                               cv::saturate_cast<uchar>(albedo[1] * s),
                               cv::saturate_cast<uchar>(albedo[2] * s));
    }
  }
  return out;
}

cv::Mat Renderer::render_face_index_orthographic(const Eigen::Vector3d& view_direction_object,
                                                 int resolution_px) const {
  if (resolution_px <= 0)
    throw std::invalid_argument("render_face_index_orthographic: resolution_px must be > 0");
  if (!(view_direction_object.norm() > 0.0) || !view_direction_object.allFinite())
    throw std::invalid_argument("render_face_index_orthographic: view direction must be non-zero");
  const Mesh& mesh = *mesh_;

  // View frame: z along the viewing direction, x and y completing a right-handed basis.
  const Eigen::Vector3d z_axis = view_direction_object.normalized();
  const Eigen::Vector3d helper =
      std::abs(z_axis.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d x_axis = helper.cross(z_axis).normalized();
  const Eigen::Vector3d y_axis = z_axis.cross(x_axis);

  const Eigen::Vector3d center = mesh.bounding_box_center();
  double radius = mesh.radius_about(center);
  if (!(radius > 0.0)) radius = 1.0;
  // [-radius, radius] covers pixels [-0.5, resolution - 0.5].
  const double scale = resolution_px / (2.0 * radius);
  const double offset = 0.5 * resolution_px - 0.5;

  std::vector<ScreenVertex> screen(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d d = mesh.vertices[i] - center;
    screen[i] = {x_axis.dot(d) * scale + offset, y_axis.dot(d) * scale + offset, -z_axis.dot(d),
                 0.0, 0.0};
  }
  Buffers buffers;
  buffers.key = cv::Mat(resolution_px, resolution_px, CV_32F,
                        cv::Scalar(-std::numeric_limits<float>::infinity()));
  buffers.face_index = cv::Mat(resolution_px, resolution_px, CV_32S, cv::Scalar(-1));
  for (int f = 0; f < static_cast<int>(mesh.faces.size()); ++f) {
    const Eigen::Vector3i& face = mesh.faces[f];
    rasterize(screen[face[0]], screen[face[1]], screen[face[2]], f, buffers);
  }
  return buffers.face_index;
}

}  // namespace kct
