// Tracker::reacquire(): contour refinement from a given pose in a widened search box, then
// keypoint tracking resumes from the result. A coarse visibility table keeps the test quick.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "klt_contour_tracker/core/tracker.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

TrackerParams quick(const std::string& preset, int visibility_resolution_px = 128) {
  TrackerParams params = make_preset(preset);
  params.icosphere_subdivisions = 2;
  params.visibility_resolution_px = visibility_resolution_px;
  return params;
}

TrackerParams quick_paper() { return quick("paper"); }

TEST(TrackerReacquire, RecoversAnOffsetPoseAndKeypointTrackingResumes) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Renderer renderer(mesh);
  const PinholeCamera camera = test::make_camera();
  const cv::Mat background = test::make_background(camera.size(), 5);
  const Pose truth = test::make_pose(0.45);
  // The last good pose is 8 mm and 4 deg away from the object's pose now.
  const Pose around = test::move(truth, 4.0, {0.3, 1.0, 0.0}, {0.008, -0.004, 0.0});
  ASSERT_GT(translation_error(around, truth), 0.008);
  Tracker tracker(mesh, camera, quick_paper());
  const cv::Mat frame = test::render_frame(renderer, camera, truth, background, 1.0, 1);
  const TrackResult result = tracker.reacquire({frame, 0.1}, around, 2.0);
  ASSERT_EQ(result.status, TrackStatus::kReacquired);
  EXPECT_TRUE(result.refined);
  EXPECT_GT(result.energy_after, result.energy_before);
  // Tolerance: 3 mm and 1.5 deg from 8 mm / 4 deg (a coarse visibility table, 12 cm box).
  EXPECT_LT(translation_error(result.object_to_camera, truth), 0.003);
  EXPECT_LT(rotation_error_deg(result.object_to_camera, truth), 1.5);
  EXPECT_TRUE(tracker.is_initialized());

  // Keypoints were re-anchored on the re-acquired pose: the next frame is tracked by KLT.
  const Pose next = test::move(truth, 1.0, {0, 1, 0}, {0.002, 0.0, 0.0});
  const TrackResult tracked =
      tracker.track({test::render_frame(renderer, camera, next, background, 1.0, 2), 0.2});
  EXPECT_EQ(tracked.status, TrackStatus::kKeypoints);
  EXPECT_LT(translation_error(tracked.object_to_camera, next), 0.004);
  EXPECT_LT(rotation_error_deg(tracked.object_to_camera, next), 2.0);
}

/// The 12 x 8 x 6 cm box at make_pose(0.45) over a textured background and `count` hypotheses
/// around it, the k-th turned by k x step_deg and moved by k x step_m.
struct HypothesisScene {
  std::shared_ptr<const Mesh> box = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  PinholeCamera camera = test::make_camera();
  Pose truth = test::make_pose(0.45);
  cv::Mat frame;
  std::vector<Pose> around;
  HypothesisScene(int count, double step_deg, const Eigen::Vector3d& step_m) {
    frame = test::render_frame(Renderer(box), camera, truth,
                               test::make_background(camera.size(), 5), 1.0, 1);
    for (int k = 0; k < count; ++k)
      around.push_back(test::move(truth, step_deg * k, {0.3, 1.0, 0.2}, step_m * k));
  }
};

TEST(TrackerReacquire, HypothesesOnTwoThreadsGiveTheOneThreadResults) {
  // Five hypotheses around the truth (an odd count: the threads get 3 and 2).
  const HypothesisScene scene(5, 2.0, {0.004, -0.002, 0.0});
  TrackerParams params = quick("realtime");
  params.num_threads = 1;
  Tracker serial(scene.box, scene.camera, params);
  params.num_threads = 2;
  Tracker parallel(scene.box, scene.camera, params);
  for (const bool shift_search : {true, false}) {
    const std::vector<TrackResult> one =
        serial.refine_hypotheses({scene.frame, 0.1}, scene.around, 1.0, shift_search);
    const std::vector<TrackResult> two =
        parallel.refine_hypotheses({scene.frame, 0.1}, scene.around, 1.0, shift_search);
    ASSERT_EQ(one.size(), scene.around.size());
    ASSERT_EQ(two.size(), scene.around.size());
    for (std::size_t i = 0; i < scene.around.size(); ++i) {
      SCOPED_TRACE(i);
      EXPECT_TRUE(one[i].refined);
      EXPECT_EQ(two[i].status, TrackStatus::kReacquired);
      // Bit for bit: each refinement depends only on its hypothesis and the frame.
      EXPECT_EQ((one[i].object_to_camera.matrix() - two[i].object_to_camera.matrix())
                    .cwiseAbs()
                    .maxCoeff(),
                0.0);
      EXPECT_EQ(one[i].energy_after, two[i].energy_after);
    }
    // The refinement did its work: the hypotheses closest to the truth end within 3 mm.
    EXPECT_LT(translation_error(two[1].object_to_camera, scene.truth), 0.003);
  }
}

/// `mesh` with every triangle split in four (midpoints shared between neighbours), `times`
/// times: the same surface with 4^times as many faces, as a scan has.
Mesh subdivided(Mesh mesh, int times) {
  for (int t = 0; t < times; ++t) {
    std::map<std::pair<int, int>, int> midpoint;
    const auto middle = [&](int a, int b) {
      const std::pair<int, int> key(std::min(a, b), std::max(a, b));
      const auto found = midpoint.find(key);
      if (found != midpoint.end()) return found->second;
      mesh.vertices.push_back(0.5 * (mesh.vertices[a] + mesh.vertices[b]));
      return midpoint[key] = static_cast<int>(mesh.vertices.size()) - 1;
    };
    std::vector<Eigen::Vector3i> faces;
    for (const Eigen::Vector3i& f : mesh.faces) {
      const int ab = middle(f[0], f[1]), bc = middle(f[1], f[2]), ca = middle(f[2], f[0]);
      faces.emplace_back(f[0], ab, ca);
      faces.emplace_back(ab, f[1], bc);
      faces.emplace_back(ca, bc, f[2]);
      faces.emplace_back(ab, bc, ca);
    }
    mesh.faces = faces;
  }
  mesh.corner_uvs.clear();
  mesh.texture.release();
  return mesh;
}

/// hypothesis_mesh_error_diameters: the hypotheses of a dense mesh refined on its simplified
/// copy end where the full mesh's do, on one thread or two.
TEST(TrackerReacquire, HypothesesOnTheSimplifiedMeshEndWhereTheFullMeshsDo) {
  // Four hypotheses within the refinement's reach: up to 3 deg and 7 mm off.
  const HypothesisScene scene(4, 1.0, {0.002, -0.001, 0.0});
  const auto dense = std::make_shared<const Mesh>(subdivided(*scene.box, 4));  // 3072 faces
  ASSERT_EQ(dense->faces.size(), 12u * 256);
  TrackerParams params = quick("realtime", 256);
  params.hypothesis_mesh_error_diameters = 0.0;
  Tracker full(dense, scene.camera, params);
  params.hypothesis_mesh_error_diameters = 0.001;
  Tracker coarse(dense, scene.camera, params);
  params.num_threads = 1;
  Tracker coarse_serial(dense, scene.camera, params);
  const std::vector<TrackResult> a =
      full.refine_hypotheses({scene.frame, 0.1}, scene.around, 1.0, true);
  const std::vector<TrackResult> b =
      coarse.refine_hypotheses({scene.frame, 0.1}, scene.around, 1.0, true);
  const std::vector<TrackResult> c =
      coarse_serial.refine_hypotheses({scene.frame, 0.1}, scene.around, 1.0, true);
  ASSERT_EQ(b.size(), scene.around.size());
  int compared = 0;
  for (std::size_t i = 0; i < scene.around.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_TRUE(b[i].refined);
    // Where the full mesh's refinement converged (3 mm / 1 deg), the simplified one ends within
    // 1 mm / 0.5 deg of it: the flat faces collapse to the box's 12 triangles, whose outline is
    // the same. (From 3 deg / 7 mm the dense mesh's refinement stops 5 deg off here and the
    // simplified one's converges: its visibility table at 256 px misses none of its faces.)
    if (translation_error(a[i].object_to_camera, scene.truth) < 0.003 &&
        rotation_error_deg(a[i].object_to_camera, scene.truth) < 1.0) {
      ++compared;
      EXPECT_LT(translation_error(a[i].object_to_camera, b[i].object_to_camera), 0.001);
      EXPECT_LT(rotation_error_deg(a[i].object_to_camera, b[i].object_to_camera), 0.5);
    }
    // The second thread's refiner is a replica of the simplified mesh's: bit for bit.
    EXPECT_EQ(
        (b[i].object_to_camera.matrix() - c[i].object_to_camera.matrix()).cwiseAbs().maxCoeff(),
        0.0);
  }
  EXPECT_GE(compared, 2);
  for (std::size_t i = 0; i < scene.around.size(); ++i) {
    EXPECT_LT(translation_error(b[i].object_to_camera, scene.truth), 0.003) << i;
    EXPECT_LT(rotation_error_deg(b[i].object_to_camera, scene.truth), 1.0) << i;
  }

  // Switched off and on again at run time: the full mesh's results, then the same again.
  params = coarse.params();
  params.hypothesis_mesh_error_diameters = 0.0;
  coarse.set_params(params);
  const std::vector<TrackResult> off =
      coarse.refine_hypotheses({scene.frame, 0.1}, scene.around, 1.0, true);
  params.hypothesis_mesh_error_diameters = 0.001;
  coarse.set_params(params);
  const std::vector<TrackResult> on =
      coarse.refine_hypotheses({scene.frame, 0.1}, scene.around, 1.0, true);
  for (std::size_t i = 0; i < scene.around.size(); ++i) {
    EXPECT_EQ(
        (off[i].object_to_camera.matrix() - a[i].object_to_camera.matrix()).cwiseAbs().maxCoeff(),
        0.0);
    EXPECT_EQ(
        (on[i].object_to_camera.matrix() - b[i].object_to_camera.matrix()).cwiseAbs().maxCoeff(),
        0.0);
  }
}

TEST(TrackerReacquire, WithoutRefinementTheGivenPoseIsTaken) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Tracker tracker(mesh, test::make_camera(), make_preset("klt_only"));
  const cv::Mat image(480, 640, CV_8UC3, cv::Scalar(90, 90, 90));
  const Pose around = test::make_pose(0.4);
  const TrackResult result = tracker.reacquire({image, 0.0}, around, 3.0);
  EXPECT_EQ(result.status, TrackStatus::kReacquired);
  EXPECT_FALSE(result.refined);
  EXPECT_LT(translation_error(result.object_to_camera, around), 1e-12);
  EXPECT_LT(translation_error(tracker.last_pose(), around), 1e-12);
}

TEST(TrackerReacquire, RejectsBadInputAndArguments) {
  auto mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Tracker tracker(mesh, test::make_camera(), make_preset("klt_only"));
  const Pose around = test::make_pose(0.4);
  EXPECT_EQ(tracker.reacquire({cv::Mat(), 0.0}, around, 2.0).status, TrackStatus::kInvalidInput);
  EXPECT_EQ(tracker.reacquire({cv::Mat(240, 320, CV_8UC1), 0.0}, around, 2.0).status,
            TrackStatus::kInvalidInput);
  EXPECT_FALSE(tracker.is_initialized());
  const cv::Mat image(480, 640, CV_8UC1, cv::Scalar(90));
  EXPECT_THROW(tracker.reacquire({image, 0.0}, around, 0.5), std::invalid_argument);
  Pose behind = around;
  behind.translation().z() = -0.4;
  EXPECT_THROW(tracker.reacquire({image, 0.0}, behind, 2.0), std::invalid_argument);
  EXPECT_STREQ(to_string(TrackStatus::kReacquired), "reacquired");
}

}  // namespace
}  // namespace kct
