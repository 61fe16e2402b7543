// track_sequence_folder() + score_sequence(): the offline pipeline of track_sequence. The same
// rendered sequence is written once in metres and once with the mesh and pose.txt in
// millimetres; read with the matching model scale, both runs give the same poses and score.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "klt_contour_tracker/core/model_units.h"
#include "klt_contour_tracker/core/sequence_io.h"
#include "klt_contour_tracker/core/sequence_run.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

namespace fs = std::filesystem;

class SequenceRunTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("kct_test_sequence_run_" +
            std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Writes `mesh` as an OBJ with coordinates divided by `metres_per_unit`.
  static void write_obj(const std::string& path, const Mesh& mesh, double metres_per_unit) {
    std::ofstream out(path);
    char line[160];
    for (const auto& v : mesh.vertices) {
      std::snprintf(line, sizeof(line), "v %.17g %.17g %.17g\n", v.x() / metres_per_unit,
                    v.y() / metres_per_unit, v.z() / metres_per_unit);
      out << line;
    }
    for (const auto& f : mesh.faces) out << "f " << f[0] + 1 << " " << f[1] + 1 << " " << f[2] + 1 << "\n";
  }

  /// A 12-frame sequence of the textured box moving slowly; returns the truth (metres).
  std::vector<Pose> write_frames(const std::string& folder, const Mesh& textured) {
    fs::create_directories(folder);
    const PinholeCamera camera = test::make_camera();
    Renderer renderer(std::make_shared<Mesh>(textured));
    const cv::Mat background = test::make_background(camera.size(), 11);
    std::vector<Pose> truth;
    for (int i = 0; i < 12; ++i) {
      const Pose pose = test::move(test::make_pose(0.45), 0.8 * i, {0.2, 1.0, 0.1}, {0.002 * i, -0.001 * i, 0.0015 * i});
      truth.push_back(pose);
      cv::imwrite(folder + "/" + frame_file_name(i), test::render_frame(renderer, camera, pose, background, 1.5, i));
    }
    write_intrinsics(folder + "/K.txt", camera.K());
    return truth;
  }

  fs::path dir_;
};

TrackerParams quick_paper() {
  TrackerParams params = make_preset("paper");
  params.icosphere_subdivisions = 2;
  params.visibility_resolution_px = 128;
  params.visibility_cache_dir = "";
  return params;
}

TEST_F(SequenceRunTest, MetresAndMillimetresGiveTheSamePosesAndScore) {
  // Half-sizes 62.5, 31.25 and 23.4375 mm are exact in float in both units (assimp stores
  // floats; scaled by 0.001 in double they give the metre values exactly): the two meshes are
  // the same, and so must the tracking be. With sizes like 60 mm the meshes differ by float
  // rounding (1e-8 relative), which the optimizer amplifies to ~0.1 mm.
  const Mesh box = test::make_box(0.125, 0.0625, 0.046875);
  const std::string folder_m = (dir_ / "metres").string(), folder_mm = (dir_ / "millimetres").string();
  const std::vector<Pose> truth = write_frames(folder_m, box);
  fs::copy(folder_m, folder_mm);
  write_pose_file(folder_m + "/pose.txt", truth);                   // metres
  write_pose_file(folder_mm + "/pose.txt", truth, ModelUnits(0.001));  // millimetres
  write_obj(folder_m + "/box.obj", box, 1.0);
  write_obj(folder_mm + "/box.obj", box, 0.001);
  // The millimetre file really is in millimetres: its first pose is 450 mm away.
  EXPECT_NEAR(read_pose_file(folder_mm + "/pose.txt").front().translation().z(), 1000.0 * truth[0].translation().z(), 1e-9);

  struct Outcome {
    SequenceRun run;
    SequenceScore score;
  };
  auto track = [](const std::string& folder, const ModelUnits& units) {
    const SequenceFolder sequence = read_sequence(folder, units);
    auto mesh = std::make_shared<Mesh>(load_mesh(folder + "/box.obj", units.metres_per_unit()));
    Outcome out;
    out.run = track_sequence_folder(sequence, mesh, quick_paper());
    out.score = score_sequence(*mesh, out.run.object_to_camera, sequence.poses);
    return out;
  };
  const Outcome metres = track(folder_m, ModelUnits(1.0));
  const Outcome millimetres = track(folder_mm, ModelUnits(0.001));

  ASSERT_EQ(metres.run.object_to_camera.size(), 12u);
  ASSERT_EQ(millimetres.run.object_to_camera.size(), 12u);
  // The tracking itself is good (so that equal poses mean something): AUC > 15 of 20.
  EXPECT_GT(metres.score.auc, 15.0);
  // Same poses to rounding: 1 micrometre, 1e-4 deg (the mm mesh differs from the metre mesh by
  // an ulp after scaling, and the optimizer is deterministic with a fixed seed).
  for (size_t i = 0; i < 12; ++i) {
    EXPECT_LT(translation_error(metres.run.object_to_camera[i], millimetres.run.object_to_camera[i]), 1e-6) << i;
    EXPECT_LT(rotation_error_deg(metres.run.object_to_camera[i], millimetres.run.object_to_camera[i]), 1e-4) << i;
  }
  EXPECT_NEAR(metres.score.auc, millimetres.score.auc, 1e-6);
  EXPECT_NEAR(metres.score.mean_add_m, millimetres.score.mean_add_m, 1e-6);
  EXPECT_NEAR(metres.score.diameter_m, millimetres.score.diameter_m, 1e-15);

  // The poses written back are in the units read: the millimetre file holds millimetres.
  write_pose_file(folder_mm + "/out.txt", millimetres.run.object_to_camera, ModelUnits(0.001));
  const std::vector<Pose> written = read_pose_file(folder_mm + "/out.txt");
  ASSERT_EQ(written.size(), 12u);
  EXPECT_NEAR(written[5].translation().z(), 1000.0 * millimetres.run.object_to_camera[5].translation().z(), 1e-9);
}

TEST_F(SequenceRunTest, TruthRefinementRefinesEachTrueFrameAndLeavesTheTrackAlone) {
  // refine_truth, a measurement aid: each frame's true pose refined as a re-acquisition
  // hypothesis is. On clean renders of a box (every rotation shows in its outline) the
  // objective holds the truth; the track is the same as without it.
  const Mesh box = test::make_box(0.12, 0.08, 0.06);
  const std::string folder = (dir_ / "box").string();
  const std::vector<Pose> truth = write_frames(folder, box);
  write_pose_file(folder + "/pose.txt", truth);
  const SequenceFolder sequence = read_sequence(folder, ModelUnits(1.0));
  auto mesh = std::make_shared<Mesh>(box);
  TrackerParams params = make_preset("realtime");
  params.icosphere_subdivisions = 2;
  params.visibility_resolution_px = 128;
  params.visibility_cache_dir = "";
  SequenceRunOptions with;
  with.refine_truth = true;
  const SequenceRun plain = track_sequence_folder(sequence, mesh, params);
  const SequenceRun refined = track_sequence_folder(sequence, mesh, params, with);

  EXPECT_TRUE(plain.truth_refined.empty());
  ASSERT_EQ(refined.truth_refined.size(), 12u);
  ASSERT_EQ(refined.object_to_camera.size(), plain.object_to_camera.size());
  for (size_t i = 0; i < plain.object_to_camera.size(); ++i)
    EXPECT_TRUE(refined.object_to_camera[i].isApprox(plain.object_to_camera[i], 0.0)) << i;
  // Frame 0 is the initial pose itself: not refined.
  EXPECT_EQ(refined.truth_refined[0].status, TrackStatus::kNotInitialized);
  const double diameter_m = mesh->diameter();
  const Eigen::Vector3d center = mesh->bounding_box_center();
  for (size_t i = 1; i < 12; ++i) {
    const TrackResult& r = refined.truth_refined[i];
    ASSERT_EQ(r.status, TrackStatus::kReacquired) << i;
    EXPECT_TRUE(r.refined) << i;
    // The refinement does not lower the energy it maximizes (1 % for its pyramid levels)...
    EXPECT_GE(r.energy_after, 0.99 * r.energy_before) << i;
    // ... and keeps the truth: within 2 % of the diameter and 2 deg.
    EXPECT_LT(((r.object_to_camera * center) - (truth[i] * center)).norm(), 0.02 * diameter_m) << i;
    EXPECT_LT(rotation_error_deg(r.object_to_camera, truth[i]), 2.0) << i;
  }
}

TEST_F(SequenceRunTest, ScoringNeedsTruthBeyondTheInitialPose) {
  const Mesh box = test::make_box(0.12, 0.08, 0.06);
  const std::vector<Pose> one = {test::make_pose(0.45)};
  try {
    score_sequence(box, {one[0], one[0], one[0]}, one);
    ADD_FAILURE() << "scored one pose";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("1 ground-truth pose(s) for 3 frame(s)"), std::string::npos) << e.what();
  }
  // Fewer truths than frames: the frames with truth are scored.
  const SequenceScore partial = score_sequence(box, {one[0], one[0], one[0]}, {one[0], one[0]});
  EXPECT_EQ(partial.scored_frames, 2u);
  EXPECT_NEAR(partial.auc, 20.0, 1e-9);
}

TEST_F(SequenceRunTest, OversizedAndUnreadableFramesGetAPerFrameErrorBeforeDecoding) {
  const Mesh box = test::make_box(0.12, 0.08, 0.06);
  const std::string folder = (dir_ / "bad").string();
  const std::vector<Pose> truth = write_frames(folder, box);
  write_pose_file(folder + "/pose.txt", truth);
  // Frame 3: a PNG header claiming 20000 x 20000 (the file is 33 bytes: decoding would need
  // 1.2 GB). Frame 5: not an image at all.
  {
    std::ofstream png(folder + "/" + frame_file_name(3), std::ios::binary | std::ios::trunc);
    const unsigned char header[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
                                    0, 0, 0x4E, 0x20, 0, 0, 0x4E, 0x20, 8, 2, 0, 0, 0};
    png.write(reinterpret_cast<const char*>(header), sizeof(header));
  }
  std::ofstream(folder + "/" + frame_file_name(5), std::ios::trunc) << "not an image";
  const SequenceFolder sequence = read_sequence(folder);
  auto mesh = std::make_shared<Mesh>(box);
  TrackerParams params = make_preset("klt_only");
  const SequenceRun run = track_sequence_folder(sequence, mesh, params);
  ASSERT_EQ(run.object_to_camera.size(), 12u);
  ASSERT_EQ(run.frame_errors.size(), 2u);
  EXPECT_NE(run.frame_errors[0].find("20000x20000"), std::string::npos) << run.frame_errors[0];
  EXPECT_NE(run.frame_errors[0].find("not decoded"), std::string::npos) << run.frame_errors[0];
  EXPECT_NE(run.frame_errors[1].find("not a PNG, JPEG or BMP"), std::string::npos) << run.frame_errors[1];
  EXPECT_EQ(run.statistics.invalid_frames, 2);
  // A skipped frame keeps the previous estimate; the frames after it are tracked.
  EXPECT_LT(translation_error(run.object_to_camera[3], run.object_to_camera[2]), 1e-12);
  EXPECT_LT(translation_error(run.object_to_camera[11], truth[11]), 0.01);

  // An oversized first frame stops the run with the reason.
  SequenceFolder first_bad = sequence;
  first_bad.image_paths.front() = first_bad.image_paths[3];
  try {
    track_sequence_folder(first_bad, mesh, params);
    ADD_FAILURE() << "tracked a 20000x20000 first frame";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("first frame unusable"), std::string::npos) << e.what();
  }
}

TEST_F(SequenceRunTest, CameraRateDropsTheFramesANewerOneReplacedWhileTracking) {
  const Mesh box = test::make_box(0.12, 0.08, 0.06);
  const std::string folder = (dir_ / "live").string();
  const std::vector<Pose> truth = write_frames(folder, box);
  write_pose_file(folder + "/pose.txt", truth);
  const SequenceFolder sequence = read_sequence(folder);
  auto mesh = std::make_shared<Mesh>(box);
  const TrackerParams params = make_preset("klt_only");
  const SequenceRun every = track_sequence_folder(sequence, mesh, params);
  EXPECT_EQ(every.dropped_frames, 0);

  // A frame every 1000 s: the tracker is always free again before the next one arrives, so
  // nothing is dropped and the poses are those of the every-frame run (klt_only is deterministic).
  SequenceRunOptions slow;
  slow.camera_rate_hz = 1e-3;
  const SequenceRun slow_run = track_sequence_folder(sequence, mesh, params, slow);
  EXPECT_EQ(slow_run.dropped_frames, 0);
  ASSERT_EQ(slow_run.object_to_camera.size(), 12u);
  for (std::size_t i = 0; i < 12; ++i)
    EXPECT_LT(translation_error(slow_run.object_to_camera[i], every.object_to_camera[i]), 1e-12) << i;

  // A million frames a second: all 12 arrive within 11 us, while the first frame (keypoint
  // detection) is being tracked. The queue then holds only the newest, the last: frames 1-10
  // are dropped and hold the first frame's pose, the last one is tracked.
  SequenceRunOptions fast;
  fast.camera_rate_hz = 1e6;
  const SequenceRun fast_run = track_sequence_folder(sequence, mesh, params, fast);
  ASSERT_EQ(fast_run.object_to_camera.size(), 12u);
  ASSERT_EQ(fast_run.dropped.size(), 12u);
  EXPECT_EQ(fast_run.dropped_frames, 10);
  EXPECT_EQ(fast_run.dropped.front(), 0);
  EXPECT_EQ(fast_run.dropped.back(), 0);
  for (std::size_t i = 1; i + 1 < 12; ++i) {
    EXPECT_EQ(fast_run.dropped[i], 1) << i;
    EXPECT_LT(translation_error(fast_run.object_to_camera[i], fast_run.object_to_camera[0]), 1e-12) << i;
  }
  EXPECT_EQ(fast_run.frame_ms.size(), 1u);  // the last frame's: the first is the initial pose

  SequenceRunOptions bad;
  bad.camera_rate_hz = -30.0;
  EXPECT_THROW(track_sequence_folder(sequence, mesh, params, bad), std::invalid_argument);
}

}  // namespace
}  // namespace kct
