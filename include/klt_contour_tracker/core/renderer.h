#pragma once
/// \file renderer.h
/// CPU z-buffer rasterizer for a Mesh. Used for synthetic data, tests, keypoint
/// back-projection (face-index buffer) and the face-visibility precomputation.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <memory>
#include <vector>

#include "klt_contour_tracker/core/camera.h"
#include "klt_contour_tracker/core/mesh.h"
#include "klt_contour_tracker/core/pose.h"

namespace kct {

class ShadowMap;

/// Shading of the colour image. With the defaults (no specular term, flat shading, no shadow
/// map) the output is the flat two-sided Lambertian shading the tests and the visibility
/// table were written against; any of the three options below switches to per-pixel shading.
struct RenderOptions {
  bool draw_color = true;  ///< produce RenderOutput::color (else only depth + face index)
  /// Direction *towards* the light in the camera frame (normalized inside).
  Eigen::Vector3d light_direction_camera{0.3, -0.5, -1.0};
  double ambient = 0.45;   ///< ambient light factor, [0, 1]
  double diffuse = 0.65;   ///< Lambertian light factor, [0, inf)
  double light_gain = 1.0; ///< global multiplier (flash / dimming effects)
  /// Blinn-Phong specular factor of a white highlight, [0, inf) (0: none). Per pixel, with
  /// the half vector of the light direction and the direction to the eye.
  double specular = 0.0;
  double shininess = 32.0;  ///< Blinn-Phong exponent, > 0 (larger: smaller, sharper highlight)
  /// Normals interpolated from area-weighted vertex normals (smooth surfaces) instead of one
  /// normal per face.
  bool smooth_shading = false;
  /// Cast shadows: the diffuse and specular terms are scaled by this map's lit fraction at
  /// each pixel's camera-frame point (not owned; must outlive the render call). Null: none.
  const ShadowMap* shadow_map = nullptr;
};

/// What one render produces; every image has the camera's size.
struct RenderOutput {
  cv::Mat color;       ///< CV_8UC3 BGR, background black (only when draw_color)
  cv::Mat depth;       ///< CV_32F camera-frame z in metres; 0 where no face
  cv::Mat face_index;  ///< CV_32S index of the visible face; -1 where no face
  cv::Mat mask() const { return face_index >= 0; }  ///< CV_8U 255 on the object
};

/// Rasterizes the mesh; faces are drawn from both sides (no back-face culling) with a z-buffer.
/// Why a CPU rasterizer and not offscreen OpenGL (EGL/OSMesa on llvmpipe): the package must
/// build and run on a headless 2-core machine without a GL stack, renders are small
/// (<= 1080p, a few per frame at most, none in the per-frame energy loop), and a pure C++
/// rasterizer is deterministic across machines, which the tests rely on.
class Renderer {
 public:
  explicit Renderer(std::shared_ptr<const Mesh> mesh);

  /// Perspective render of the mesh at `object_to_camera` with the camera's intrinsics.
  RenderOutput render(const Pose& object_to_camera, const PinholeCamera& camera,
                      const RenderOptions& options = {}) const;

  /// render(...).mask() without the depth test or the depth and face buffers (the same
  /// pixels; checked in the tests): CV_8U, 255 on the object. The colour search renders two
  /// dozen silhouettes a frame.
  cv::Mat render_silhouette(const Pose& object_to_camera, const PinholeCamera& camera) const;

  /// Orthographic face-index render looking along `view_direction_object` (object frame,
  /// from the eye towards the object), `resolution_px` square pixels covering the model's
  /// bounding sphere. Used by the visibility table (paper supplement, Sec. 3).
  cv::Mat render_face_index_orthographic(const Eigen::Vector3d& view_direction_object,
                                         int resolution_px) const;

  const Mesh& mesh() const { return *mesh_; }

 private:
  /// Per-pixel shading (specular, smooth normals, shadows) of a finished depth/face render.
  void shade_per_pixel(const Pose& object_to_camera, const PinholeCamera& camera,
                       const RenderOptions& options,
                       const std::vector<Eigen::Vector3d>& points_camera, const cv::Mat& uv,
                       RenderOutput& out) const;

  std::shared_ptr<const Mesh> mesh_;
};

}  // namespace kct
