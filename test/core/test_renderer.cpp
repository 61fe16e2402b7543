#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "klt_contour_tracker/core/renderer.h"
#include "synthetic_scene.h"

namespace {

using kct::test::make_cube;

const kct::PinholeCamera kCamera(500.0, 480.0, 319.5, 239.5, 640, 480);

kct::Pose make_pose(const Eigen::Vector3d& axis, double angle, const Eigen::Vector3d& t) {
  kct::Pose pose = kct::Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  pose.translation() = t;
  return pose;
}

/// Convex hull of the projected vertices: the exact silhouette of a convex mesh.
std::vector<cv::Point2f> projected_hull(const kct::Mesh& mesh, const kct::Pose& pose) {
  std::vector<cv::Point2f> points, hull;
  for (const auto& v : mesh.vertices) {
    const Eigen::Vector2d p = kCamera.project(pose * v);
    points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
  }
  cv::convexHull(points, hull);
  return hull;
}

}  // namespace

TEST(Renderer, CubeSilhouetteMatchesAnalyticProjection) {
  const auto cube = make_cube(0.1);
  const kct::Renderer renderer(cube);
  const std::vector<kct::Pose> poses = {
      make_pose({0, 0, 1}, 0.0, {0.0, 0.0, 0.5}),
      make_pose({1, 2, 0.5}, 0.7, {0.03, -0.02, 0.45}),
      make_pose({-0.3, 1, 0.2}, 2.1, {-0.08, 0.05, 0.7}),
  };
  for (const auto& pose : poses) {
    const kct::RenderOutput out = renderer.render(pose, kCamera);
    ASSERT_EQ(out.depth.type(), CV_32F);
    ASSERT_EQ(out.face_index.type(), CV_32S);
    ASSERT_EQ(out.color.type(), CV_8UC3);
    const std::vector<cv::Point2f> hull = projected_hull(*cube, pose);
    const double area = cv::contourArea(hull), perimeter = cv::arcLength(hull, true);
    const int count = cv::countNonZero(out.mask());
    // Pixel-centre sampling of a polygon: the count deviates from the area by a fraction of
    // the perimeter (exactly 0 for ideal sampling on average).
    EXPECT_NEAR(count, area, 0.1 * perimeter) << "area " << area;

    const cv::Rect box = cv::boundingRect(out.mask());
    float x_min = 1e9f, y_min = 1e9f, x_max = -1e9f, y_max = -1e9f;
    for (const auto& p : hull) {
      x_min = std::min(x_min, p.x), x_max = std::max(x_max, p.x);
      y_min = std::min(y_min, p.y), y_max = std::max(y_max, p.y);
    }
    // No covered pixel centre outside the analytic extent, and the first / last covered
    // centres within 2 px of it (a sharp corner's tip can fall between pixel centres).
    EXPECT_GE(box.x, x_min - 1e-3);
    EXPECT_GE(box.y, y_min - 1e-3);
    EXPECT_LE(box.x + box.width - 1, x_max + 1e-3);
    EXPECT_LE(box.y + box.height - 1, y_max + 1e-3);
    EXPECT_LT(box.x - x_min, 2.0);
    EXPECT_LT(box.y - y_min, 2.0);
    EXPECT_LT(x_max - (box.x + box.width - 1), 2.0);
    EXPECT_LT(y_max - (box.y + box.height - 1), 2.0);

    // Every pixel is either background (-1, depth 0) or a valid face with positive depth.
    for (int y = 0; y < out.face_index.rows; ++y)
      for (int x = 0; x < out.face_index.cols; ++x) {
        const int f = out.face_index.at<int>(y, x);
        ASSERT_GE(f, -1);
        ASSERT_LT(f, static_cast<int>(cube->faces.size()));
        EXPECT_EQ(f >= 0, out.depth.at<float>(y, x) > 0.0f);
        EXPECT_EQ(f >= 0, out.color.at<cv::Vec3b>(y, x) != cv::Vec3b(0, 0, 0));
      }
  }
}

TEST(Renderer, DepthAtCentreAndBackProjectionLandOnTheMesh) {
  const auto cube = make_cube(0.1);
  const kct::Renderer renderer(cube);
  {
    const kct::RenderOutput out =
        renderer.render(make_pose({0, 0, 1}, 0.0, {0.0, 0.0, 0.5}), kCamera);
    // The principal point sees the front face at z = 0.5 - 0.05 (pixel 319.5 -> average).
    const float centre = out.depth.at<float>(240, 320);
    EXPECT_NEAR(centre, 0.45, 1e-6);
  }
  const kct::Pose pose = make_pose({1, -1, 0.3}, 0.9, {0.02, 0.01, 0.4});
  const kct::RenderOutput out = renderer.render(pose, kCamera);
  const kct::Pose camera_to_object = pose.inverse();
  int checked = 0;
  for (int y = 0; y < out.depth.rows; y += 7)
    for (int x = 0; x < out.depth.cols; x += 7) {
      const int f = out.face_index.at<int>(y, x);
      if (f < 0) continue;
      const Eigen::Vector3d point_camera =
          out.depth.at<float>(y, x) * kCamera.back_project(Eigen::Vector2d(x, y));
      const Eigen::Vector3d p = camera_to_object * point_camera;
      // On the face's plane and inside its triangle (barycentric coordinates >= 0).
      const Eigen::Vector3i& face = cube->faces[f];
      const Eigen::Vector3d a = cube->vertices[face[0]], b = cube->vertices[face[1]],
                            c = cube->vertices[face[2]];
      const Eigen::Vector3d n = cube->face_normal(f);
      EXPECT_NEAR(n.dot(p - a), 0.0, 2e-5);  // float depth at 0.4 m: ~1e-7 relative
      const double total = n.dot((b - a).cross(c - a));
      const double wa = n.dot((b - p).cross(c - p)) / total;
      const double wb = n.dot((c - p).cross(a - p)) / total;
      const double wc = 1.0 - wa - wb;
      EXPECT_GT(std::min({wa, wb, wc}), -1e-3);
      // The visible face of a convex object faces the camera.
      EXPECT_LT((pose.linear() * n).dot(point_camera), 0.0);
      ++checked;
    }
  EXPECT_GT(checked, 100);
}

TEST(Renderer, CameraInsideTheCubeSeesItsInsideEverywhere) {
  // Side faces cross the camera plane: they must be clipped at the near plane, not wrapped.
  const auto cube = make_cube(0.1);
  const kct::Renderer renderer(cube);
  const kct::RenderOutput out =
      renderer.render(make_pose({0, 0, 1}, 0.0, {0.0, 0.0, 0.03}), kCamera);
  EXPECT_EQ(cv::countNonZero(out.mask()), kCamera.width() * kCamera.height());
  EXPECT_NEAR(out.depth.at<float>(240, 320), 0.08, 1e-6);
  // A pixel looking at a side wall: x = 0.05 at depth z where the ray meets it.
  const double u = 620.0, z = 0.05 / ((u - kCamera.cx()) / kCamera.fx());
  EXPECT_NEAR(out.depth.at<float>(240, static_cast<int>(u)), std::min(z, 0.08), 1e-5);
}

TEST(Renderer, TextureIsPerspectiveCorrectAndUpright) {
  // A square textured with four coloured quadrants (top-left red, top-right green, bottom-left
  // blue, bottom-right white), tilted 55 degrees about the vertical axis.
  auto quad = std::make_shared<kct::Mesh>();
  const double h = 0.05;
  quad->vertices = {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};  // object y up
  quad->faces = {{0, 1, 2}, {0, 2, 3}};
  auto uv = [&](int i) {
    return Eigen::Vector2f(static_cast<float>((quad->vertices[i].x() + h) / (2 * h)),
                           static_cast<float>((quad->vertices[i].y() + h) / (2 * h)));
  };
  for (const auto& f : quad->faces)
    for (int k = 0; k < 3; ++k) quad->corner_uvs.push_back(uv(f[k]));
  quad->texture = cv::Mat(64, 64, CV_8UC3);
  quad->texture(cv::Rect(0, 0, 32, 32)).setTo(cv::Scalar(0, 0, 255));
  quad->texture(cv::Rect(32, 0, 32, 32)).setTo(cv::Scalar(0, 255, 0));
  quad->texture(cv::Rect(0, 32, 32, 32)).setTo(cv::Scalar(255, 0, 0));
  quad->texture(cv::Rect(32, 32, 32, 32)).setTo(cv::Scalar(255, 255, 255));
  ASSERT_TRUE(quad->has_texture());

  // Object x -> image right, object y -> image up, then the tilt about the image vertical.
  kct::Pose pose = kct::Pose::Identity();
  pose.linear() = Eigen::AngleAxisd(55.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()) *
                  Eigen::Vector3d(1, -1, -1).asDiagonal();
  pose.translation() = Eigen::Vector3d(0, 0, 0.3);
  kct::RenderOptions unlit;
  unlit.ambient = 1.0;
  unlit.diffuse = 0.0;
  const kct::RenderOutput out = kct::Renderer(quad).render(pose, kCamera, unlit);

  // Perspective-correct: the texture's vertical midline is the projection of x = 0, which
  // is several pixels away from the midpoint of the projected left and right edges.
  const double mid_u = kCamera.project(pose * Eigen::Vector3d(0, 0, 0)).x();
  const double affine_mid_u = 0.5 * (kCamera.project(pose * Eigen::Vector3d(-h, 0, 0)).x() +
                                     kCamera.project(pose * Eigen::Vector3d(h, 0, 0)).x());
  ASSERT_GT(std::abs(mid_u - affine_mid_u), 5.0);
  const int top = static_cast<int>(kCamera.project(pose * Eigen::Vector3d(0, 0.5 * h, 0)).y());
  const int bottom = static_cast<int>(kCamera.project(pose * Eigen::Vector3d(0, -0.5 * h, 0)).y());
  auto color_at = [&](double x, int y) {
    return out.color.at<cv::Vec3b>(y, static_cast<int>(std::lround(x)));
  };
  EXPECT_EQ(color_at(mid_u - 2, top), cv::Vec3b(0, 0, 255));
  EXPECT_EQ(color_at(mid_u + 2, top), cv::Vec3b(0, 255, 0));
  EXPECT_EQ(color_at(mid_u - 2, bottom), cv::Vec3b(255, 0, 0));
  EXPECT_EQ(color_at(mid_u + 2, bottom), cv::Vec3b(255, 255, 255));
}

TEST(Renderer, LightGainAndUntexturedBaseColor) {
  const auto cube = make_cube(0.1);
  cube->base_color = cv::Vec3b(100, 150, 200);
  const kct::Renderer renderer(cube);
  const kct::Pose pose = make_pose({0, 0, 1}, 0.0, {0.0, 0.0, 0.5});
  kct::RenderOptions options;
  options.light_direction_camera = Eigen::Vector3d(0, 0, -1);  // head-on: |n.l| = 1
  options.ambient = 0.2;
  options.diffuse = 0.6;
  const cv::Vec3b lit = renderer.render(pose, kCamera, options).color.at<cv::Vec3b>(240, 320);
  EXPECT_EQ(lit, cv::Vec3b(80, 120, 160));
  options.light_gain = 0.5;
  const cv::Vec3b dim = renderer.render(pose, kCamera, options).color.at<cv::Vec3b>(240, 320);
  EXPECT_EQ(dim, cv::Vec3b(40, 60, 80));
  options.draw_color = false;
  EXPECT_TRUE(renderer.render(pose, kCamera, options).color.empty());
}

TEST(Renderer, OrthographicFaceIndexSeesOnlyFrontFaces) {
  const auto cube = make_cube(0.1);
  const kct::Renderer renderer(cube);
  const int resolution = 200;
  for (const Eigen::Vector3d& direction :
       {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(-0.2, 0.7, -0.4)}) {
    const cv::Mat index = renderer.render_face_index_orthographic(direction, resolution);
    ASSERT_EQ(index.type(), CV_32S);
    ASSERT_EQ(index.size(), cv::Size(resolution, resolution));
    std::vector<int> seen(cube->faces.size(), 0);
    for (int y = 0; y < resolution; ++y)
      for (int x = 0; x < resolution; ++x) {
        const int f = index.at<int>(y, x);
        if (f < 0) continue;
        ASSERT_LT(f, static_cast<int>(cube->faces.size()));
        ++seen[f];
        EXPECT_LT(cube->face_normal(f).dot(direction), 0.0) << "back face " << f << " visible";
      }
    // Every front-facing face shows up.
    for (int f = 0; f < static_cast<int>(cube->faces.size()); ++f)
      if (cube->face_normal(f).dot(direction.normalized()) < -0.1) {
        EXPECT_GT(seen[f], 0) << f;
      }
  }
  // Looking along +z: the square of side 0.1 inside a bounding sphere of radius 0.05 sqrt(3).
  const cv::Mat index = renderer.render_face_index_orthographic({0, 0, 1}, resolution);
  const double side_px = 0.1 * resolution / (0.1 * std::sqrt(3.0));
  EXPECT_NEAR(cv::countNonZero(index >= 0), side_px * side_px, 2.0 * side_px);
  EXPECT_THROW(renderer.render_face_index_orthographic({0, 0, 0}, resolution),
               std::invalid_argument);
}

namespace {

/// A large square (two triangles) in the plane z = 0 of its frame, facing -z... and +z.
std::shared_ptr<kct::Mesh> make_square(double half) {
  auto mesh = std::make_shared<kct::Mesh>();
  mesh->vertices = {{-half, -half, 0}, {half, -half, 0}, {half, half, 0}, {-half, half, 0}};
  mesh->faces = {{0, 1, 2}, {0, 2, 3}};
  mesh->base_color = cv::Vec3b(100, 100, 100);
  return mesh;
}

}  // namespace

TEST(Renderer, SpecularHighlightIsWhereTheHalfVectorMeetsTheNormal) {
  // A wall facing the camera, light from the camera: Blinn-Phong's highlight is at the image
  // point whose view ray is along the normal, i.e. the principal point; diffuse-only shading
  // (flat) is uniform.
  const auto wall = make_square(0.5);
  const kct::Renderer renderer(wall);
  const kct::Pose pose = make_pose({0, 0, 1}, 0.0, {0.0, 0.0, 0.5});
  kct::RenderOptions options;
  options.light_direction_camera = Eigen::Vector3d(0, 0, -1);
  const cv::Mat flat = renderer.render(pose, kCamera, options).color;
  options.specular = 0.5;
  options.shininess = 50.0;
  const cv::Mat shiny = renderer.render(pose, kCamera, options).color;
  const auto grey = [](const cv::Mat& image, int x, int y) { return image.at<cv::Vec3b>(y, x)[1]; };
  EXPECT_EQ(grey(flat, 320, 240), grey(flat, 20, 20));                // flat: uniform
  EXPECT_GT(grey(shiny, 320, 240), grey(flat, 320, 240) + 60);        // highlight at the centre
  EXPECT_LT(std::abs(grey(shiny, 20, 20) - grey(flat, 20, 20)), 15);  // none at the corner
  // Defaults unchanged: the per-pixel path is off unless asked for.
  EXPECT_EQ(cv::norm(renderer.render(pose, kCamera).color,
                     renderer.render(pose, kCamera, kct::RenderOptions{}).color, cv::NORM_INF),
            0.0);
}

TEST(Renderer, SmoothShadingVariesAcrossAFaceFlatDoesNot) {
  const auto cube = make_cube(0.1);
  const kct::Renderer renderer(cube);
  const kct::Pose pose = make_pose({1, 1, 0}, 0.6, {0.0, 0.0, 0.5});
  kct::RenderOptions options;
  options.specular = 1e-9;  // per-pixel path, no visible highlight
  const kct::RenderOutput flat = renderer.render(pose, kCamera, options);
  options.smooth_shading = true;
  const kct::RenderOutput smooth = renderer.render(pose, kCamera, options);
  // Within one face, flat shading has one grey level; smooth shading a range of them.
  const int face = flat.face_index.at<int>(240, 320);
  ASSERT_GE(face, 0);
  double flat_min = 255, flat_max = 0, smooth_min = 255, smooth_max = 0;
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) {
      if (flat.face_index.at<int>(y, x) != face) continue;
      const double f = flat.color.at<cv::Vec3b>(y, x)[0], s = smooth.color.at<cv::Vec3b>(y, x)[0];
      flat_min = std::min(flat_min, f), flat_max = std::max(flat_max, f);
      smooth_min = std::min(smooth_min, s), smooth_max = std::max(smooth_max, s);
    }
  EXPECT_LE(flat_max - flat_min, 1.0);
  EXPECT_GT(smooth_max - smooth_min, 10.0);
}

TEST(Renderer, SilhouetteIsTheDepthTestedRendersMask) {
  // Two overlapping boxes (faces drawn over each other), a cube and an open mesh (the cube
  // without its front face); poses whole in view, partly outside, and crossing the camera
  // plane (near-plane clipping).
  auto overlapping = std::make_shared<kct::Mesh>(kct::test::make_box(0.08, 0.05, 0.04, false));
  const kct::Mesh second = kct::test::make_box(0.03, 0.09, 0.06, false);
  const int offset = static_cast<int>(overlapping->vertices.size());
  for (const Eigen::Vector3d& v : second.vertices)
    overlapping->vertices.push_back(v + Eigen::Vector3d(0.02, 0.01, -0.01));
  for (const Eigen::Vector3i& f : second.faces)
    overlapping->faces.push_back(f + Eigen::Vector3i::Constant(offset));
  auto open = std::make_shared<kct::Mesh>(*make_cube(0.1));
  open->faces.pop_back();
  open->faces.pop_back();
  const std::vector<kct::Pose> poses{make_pose({0.3, 1.0, 0.2}, 0.7, {0.0, 0.0, 0.4}),
                                     make_pose({1.0, 0.2, 0.0}, 2.1, {0.25, -0.1, 0.35}),
                                     make_pose({0, 0, 1}, 0.0, {0.0, 0.0, 0.03}),
                                     make_pose({0.0, 1.0, 0.0}, 1.2, {0.03, 0.01, 0.02})};
  int compared = 0;
  for (const std::shared_ptr<const kct::Mesh>& mesh :
       {std::shared_ptr<const kct::Mesh>(overlapping),
        std::shared_ptr<const kct::Mesh>(make_cube(0.1)), std::shared_ptr<const kct::Mesh>(open)}) {
    const kct::Renderer renderer(mesh);
    kct::RenderOptions options;
    options.draw_color = false;
    for (const kct::Pose& pose : poses) {
      const cv::Mat expected = renderer.render(pose, kCamera, options).mask();
      const cv::Mat silhouette = renderer.render_silhouette(pose, kCamera);
      ASSERT_EQ(silhouette.type(), CV_8UC1);
      ASSERT_EQ(silhouette.size(), expected.size());
      EXPECT_EQ(cv::countNonZero(silhouette != expected), 0);
      if (cv::countNonZero(expected) > 0) ++compared;
    }
  }
  EXPECT_GE(compared, 10);  // most cases draw something
}

TEST(Renderer, SilhouetteOfRandomTrianglesIsTheDepthTestedRendersMask) {
  // Any triangle (slivers, near-horizontal and near-vertical edges, ones about a pixel across,
  // ones reaching out of the image or through the near plane) covers exactly the pixels in the
  // silhouette that it covers in the depth-tested render (the colour search scores poses by
  // silhouettes, the rest of the tracker reads the depth-tested render).
  cv::RNG rng(12345);
  auto mesh = std::make_shared<kct::Mesh>();
  const auto random_point = [&](double spread) {
    return Eigen::Vector3d(rng.uniform(-spread, spread), rng.uniform(-spread, spread),
                           rng.uniform(-spread, spread));
  };
  for (int i = 0; i < 150; ++i) {
    const Eigen::Vector3d a = random_point(0.1);
    Eigen::Vector3d b = a + random_point(0.08), c = a + random_point(0.08);
    if (i % 5 == 1) c = a + 0.999 * (b - a) + random_point(1e-4);              // a sliver
    if (i % 5 == 2) b = a + Eigen::Vector3d(rng.uniform(-0.1, 0.1), 1e-7, 0);  // near-horizontal
    if (i % 5 == 3) b = a + Eigen::Vector3d(1e-7, rng.uniform(-0.1, 0.1), 0);  // near-vertical
    if (i % 5 == 4) {  // about a pixel across
      b = a + random_point(3e-4);
      c = a + random_point(3e-4);
    }
    const int first = static_cast<int>(mesh->vertices.size());
    mesh->vertices.insert(mesh->vertices.end(), {a, b, c});
    mesh->faces.emplace_back(first, first + 1, first + 2);
  }
  const kct::Renderer renderer(mesh);
  kct::RenderOptions options;
  options.draw_color = false;
  for (int k = 0; k < 12; ++k) {
    // Whole in view (0.4 m), partly out of the image (0.25 m), through the near plane (0.05 m).
    const double z = k % 3 == 0 ? 0.4 : k % 3 == 1 ? 0.25 : 0.05;
    const kct::Pose pose =
        make_pose(random_point(1.0) + Eigen::Vector3d(0, 0, 1.5), rng.uniform(0.0, 3.0),
                  {rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), z});
    const cv::Mat expected = renderer.render(pose, kCamera, options).mask();
    const cv::Mat silhouette = renderer.render_silhouette(pose, kCamera);
    ASSERT_GT(cv::countNonZero(expected), 0) << "pose " << k;
    EXPECT_EQ(cv::countNonZero(silhouette != expected), 0) << "pose " << k;
  }
}
