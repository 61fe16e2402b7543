// TrackingSession: the pipeline + loss detection + re-acquisition + restart on a backward time
// jump behind one track() call. A coarse visibility table keeps the test quick.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "klt_contour_tracker/core/tracking_session.h"
#include "synthetic_scene.h"

namespace kct {
namespace {

TrackerParams quick_paper() {
  TrackerParams params = make_preset("paper");
  params.icosphere_subdivisions = 2;
  params.visibility_resolution_px = 128;
  params.visibility_cache_dir = "";
  return params;
}

struct Scene {
  std::shared_ptr<Mesh> mesh = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
  Renderer renderer{mesh};
  PinholeCamera camera = test::make_camera();
  cv::Mat background = test::make_background(camera.size(), 5);
  /// The object's pose at frame i: a slow drift.
  Pose pose(int i) const {
    return test::move(test::make_pose(0.45), 0.5 * i, {0.2, 1.0, 0.0}, {0.0015 * i, -0.0005 * i, 0.0});
  }
  /// The box at `object_to_camera` on the background, noise seeded by `seed`.
  cv::Mat render(const Pose& object_to_camera, int seed) const {
    return test::render_frame(renderer, camera, object_to_camera, background, 1.5, seed);
  }
  cv::Mat visible(int i) const { return render(pose(i), i); }
  /// `session` initialized at path(0), then frames 0 .. frames - 1 rendered at path(i) (noise
  /// seed i), stamped 1.0 s + i x 0.033 s and tracked: their results.
  template <typename Path>
  std::vector<SessionResult> follow(TrackingSession& session, const Path& path, int frames) const {
    session.initialize(path(0));
    std::vector<SessionResult> results;
    double stamp = 1.0;
    for (int i = 0; i < frames; ++i, stamp += 0.033) results.push_back(session.track({render(path(i), i), stamp}));
    return results;
  }
  /// The object hidden: the background alone.
  cv::Mat hidden(int i) const {
    cv::Mat frame = background.clone();
    cv::Mat noise(frame.size(), CV_8UC3);
    cv::RNG(i).fill(noise, cv::RNG::UNIFORM, 0, 3);
    return frame + noise;
  }
};

/// drop_unconfirmed_anchors: the object vanishes; the first hidden frame's KLT fails, the
/// refinement ends on background and keypoints are anchored there. Kept, the next frame's KLT
/// follows them (the background does not move); dropped, the next frame has none to follow.
TEST(TrackingSession, AnchorsLaidOnABadFrameAreDroppedWhenAsked) {
  const Scene scene;
  for (const bool drop : {false, true}) {
    TrackerParams params = quick_paper();
    params.drop_unconfirmed_anchors = drop;
    TrackingSession session(scene.mesh, params);
    session.set_camera(scene.camera);
    session.initialize(scene.pose(0));
    double stamp = 1.0;
    for (int frame = 0; frame < 6; ++frame, stamp += 0.033)
      ASSERT_TRUE(session.track({scene.visible(frame), stamp}).good) << frame;
    const SessionResult first = session.track({scene.hidden(6), stamp += 0.033});
    ASSERT_EQ(first.frame.status, TrackStatus::kExtrapolated) << "KLT fails when the object vanishes";
    ASSERT_FALSE(first.good);
    const SessionResult next = session.track({scene.hidden(7), stamp += 0.033});
    ASSERT_EQ(next.state, TrackState::kTracking) << "not lost yet: the tracker ran";
    if (drop)
      EXPECT_EQ(next.frame.keypoints.tracked, 0) << "the anchors of the bad frame were dropped";
    else
      EXPECT_GT(next.frame.keypoints.tracked, 8) << "the anchors on the background were followed";
  }
}

/// track_while_lost: the monitor is made to judge nearly every frame bad (the energy ratio alone,
/// good only at or above its level), so the session is LOST from about the sixth frame while the
/// box, in plain view, slides 4 mm a frame.
/// Refined around the last good pose (the given one) every lost frame, the pose stays behind;
/// tracked from where the last frame ended, it follows the box.
TEST(TrackingSession, WhileLostAMovingObjectIsTrackedFromWhereTheLastFrameEnded) {
  const Scene scene;
  const auto pose = [&](int i) {
    return test::move(scene.pose(0), 0.3 * i, {0.2, 1.0, 0.0}, {0.004 * i, 0.001 * i, 0.0});
  };
  TrackQualityParams quality;
  quality.min_quality = 1.0;
  quality.energy_weight = 1.0;  // the energy ratio alone, below 1 after the first frames
  for (const bool track_while_lost : {false, true}) {
    TrackerParams params = quick_paper();
    params.track_while_lost = track_while_lost;
    TrackingSession session(scene.mesh, params, quality);
    session.set_camera(scene.camera);
    const std::vector<SessionResult> results = scene.follow(session, pose, 25);
    const auto lost_frames = std::count_if(results.begin(), results.end(), [](const SessionResult& r) {
      return r.state == TrackState::kLost;
    });
    ASSERT_GE(lost_frames, 15) << "the monitor must keep the session lost";
    const double error_m = translation_error(results.back().frame.object_to_camera, pose(24));
    if (track_while_lost)
      EXPECT_LT(error_m, 0.005) << "followed while lost";
    else
      EXPECT_GT(error_m, 0.03) << "refined around the last good pose, 96 mm behind";
  }
}

/// trusted_depth_ratio: the trusted depth follows a good track, so a box that moves from 0.45 m
/// to 1.0 m (2.2x, beyond the ratio 2 of the given pose's depth) stays tracked and good; a range
/// frozen at the given pose's depth would declare the last frames bad and the track lost.
TEST(TrackingSession, TheTrustedDepthFollowsAGoodTrack) {
  const Scene scene;
  const auto pose = [&](int i) { return test::move(test::make_pose(0.45), 0.0, {0, 0, 1}, {0, 0, 0.016 * i}); };
  TrackerParams params = quick_paper();
  params.trusted_depth_ratio = 2.0;
  TrackingSession session(scene.mesh, params);
  session.set_camera(scene.camera);
  const std::vector<SessionResult> results = scene.follow(session, pose, 35);
  const SessionResult& last = results.back();
  const auto bad = std::count_if(results.begin(), results.end(), [](const SessionResult& r) { return !r.good; });
  ASSERT_GT(pose(34).translation().z(), 2.0 * 0.45) << "the box must leave the given pose's range";
  EXPECT_EQ(last.state, TrackState::kTracking);
  EXPECT_LE(bad, 2);
  EXPECT_LT(translation_error(last.frame.object_to_camera, pose(34)), 0.02);
}

/// repeat_recover_diameters: the monitor is made to judge every find bad by its score (no
/// keypoints, k = 0, caps it at 0.5 below a min_quality of 1) and KLT frames nearly always, so the
/// session gets LOST on the box standing in plain view; every lost frame is then a find (refined
/// around the last good pose) at the same place. Judged by the score alone it never recovers;
/// with the repeated find counted as good it recovers on the second find (one good frame
/// recovers here: the KLT frame after a good find is bad by this monitor), on the right pose.
TEST(TrackingSession, AFindRepeatedWhileLostRecoversTheTrack) {
  const Scene scene;
  TrackQualityParams quality;
  quality.min_quality = 1.0;
  quality.energy_weight = 0.5;
  quality.recover_after_good_frames = 1;
  for (const double repeat : {0.0, make_preset("realtime").repeat_recover_diameters}) {
    TrackerParams params = quick_paper();
    params.repeat_recover_diameters = repeat;
    params.repeat_recover_deg = make_preset("realtime").repeat_recover_deg;
    TrackingSession session(scene.mesh, params, quality);
    session.set_camera(scene.camera);
    session.initialize(scene.pose(0));
    double stamp = 1.0;
    int lost_at = -1, recovered_at = -1;
    SessionResult recovered;
    for (int i = 0; i < 30 && recovered_at < 0; ++i, stamp += 0.033) {
      const SessionResult r = session.track({scene.render(scene.pose(0), i), stamp});
      if (lost_at < 0 && r.state == TrackState::kLost) lost_at = i;
      if (lost_at >= 0 && recovered_at < 0 && r.state == TrackState::kTracking) {
        recovered_at = i;
        recovered = r;
      }
    }
    ASSERT_GE(lost_at, 0) << "the monitor must make the session lose the box";
    if (repeat > 0.0) {
      ASSERT_GE(recovered_at, 0) << "repeated finds recover the track";
      EXPECT_LE(recovered_at - lost_at, 2) << "the first find, then the same place again";
      EXPECT_LT(translation_error(recovered.frame.object_to_camera, scene.pose(0)), 0.005);
    } else {
      EXPECT_LT(recovered_at, 0) << "a find scores at most 0.5: never good by its score";
    }
  }
}

TEST(TrackingSession, LosesTheHiddenObjectAndReacquiresItWhenItComesBack) {
  const Scene scene;
  TrackingSession session(scene.mesh, quick_paper());
  EXPECT_FALSE(session.has_camera());
  EXPECT_EQ(session.track({scene.visible(0), 0.0}).frame.status, TrackStatus::kNotInitialized);
  session.set_camera(scene.camera);
  session.initialize(scene.pose(0));
  int frame = 0;
  double stamp = 1.0;
  // Frames 0-5 visible: tracked.
  for (; frame < 6; ++frame, stamp += 0.033) {
    const SessionResult r = session.track({scene.visible(frame), stamp});
    ASSERT_TRUE(r.has_pose());
    EXPECT_EQ(r.state, TrackState::kTracking) << frame;
    EXPECT_LT(translation_error(r.frame.object_to_camera, scene.pose(frame)), 0.005) << frame;
  }
  // Frames 6-17 hidden: LOST within lost_after_bad_frames (3) + 2 frames (the energy level
  // drops at once when the contour sits on background only; KLT fails at once).
  const int lost_after = session.quality_params().lost_after_bad_frames;
  int lost_at = -1;
  for (; frame < 18; ++frame, stamp += 0.033) {
    const SessionResult r = session.track({scene.hidden(frame), stamp});
    if (r.state == TrackState::kLost && lost_at < 0) lost_at = frame;
  }
  ASSERT_GE(lost_at, 6);
  EXPECT_LE(lost_at, 6 + lost_after + 2);
  EXPECT_EQ(session.state(), TrackState::kLost);
  EXPECT_EQ(session.statistics().losses, 1);
  EXPECT_GE(session.statistics().frames_lost, 18 - (6 + lost_after + 2));
  // Back in view where it was lost (slow drift): re-acquired within 10 frames, pose right.
  int back_at = -1;
  for (int k = 0; k < 10; ++k, ++frame, stamp += 0.033) {
    const SessionResult r = session.track({scene.visible(6 + k), stamp});
    if (k == 0) {
      EXPECT_TRUE(r.reacquiring);
    }
    if (r.state == TrackState::kTracking) {
      back_at = k;
      EXPECT_LT(translation_error(r.frame.object_to_camera, scene.pose(6 + k)), 0.005);
      EXPECT_LT(rotation_error_deg(r.frame.object_to_camera, scene.pose(6 + k)), 2.0);
      break;
    }
  }
  ASSERT_GE(back_at, 0) << "not re-acquired within 10 frames";
  EXPECT_EQ(session.statistics().reacquisitions, 1);
  ASSERT_EQ(session.statistics().frames_to_reacquire.size(), 1u);
  EXPECT_GT(session.statistics().frames_to_reacquire[0], 0);
}

TEST(TrackingSession, BackwardTimeJumpRestartsFromTheRestartPose) {
  const Scene scene;
  TrackingSession session(scene.mesh, make_preset("klt_only"));
  session.set_camera(scene.camera);
  session.set_restart_pose(scene.pose(0));
  session.initialize(scene.pose(0));
  for (int i = 0; i < 8; ++i) session.track({scene.visible(i), 10.0 + 0.033 * i});
  EXPECT_GT(translation_error(session.tracker().last_pose(), scene.pose(0)), 0.005);
  EXPECT_TRUE(session.time_jumps_back(5.0));
  EXPECT_FALSE(session.time_jumps_back(20.0));
  // A looping bag: frame 0 again, stamped earlier.
  const SessionResult jumped = session.track({scene.visible(0), 10.0});
  EXPECT_TRUE(jumped.time_jumped_back);
  EXPECT_TRUE(jumped.restarted);
  EXPECT_EQ(jumped.frame.status, TrackStatus::kInitialized);
  EXPECT_LT(translation_error(jumped.frame.object_to_camera, scene.pose(0)), 1e-12);
  EXPECT_EQ(session.statistics().restarts, 1);
  // Tracking continues from it.
  const SessionResult next = session.track({scene.visible(1), 10.033});
  EXPECT_EQ(next.frame.status, TrackStatus::kKeypoints);
  EXPECT_LT(translation_error(next.frame.object_to_camera, scene.pose(1)), 0.005);

  // A pose given just before the jump wins over the restart pose.
  session.track({scene.visible(2), 10.066});
  session.initialize(scene.pose(3));
  const SessionResult given = session.track({scene.visible(3), 0.5});
  EXPECT_TRUE(given.time_jumped_back);
  EXPECT_FALSE(given.restarted);
  EXPECT_LT(translation_error(given.frame.object_to_camera, scene.pose(3)), 1e-12);

  // Without a restart pose, a jump keeps tracking.
  session.set_restart_pose(std::nullopt);
  const SessionResult kept = session.track({scene.visible(4), 0.1});
  EXPECT_TRUE(kept.time_jumped_back);
  EXPECT_FALSE(kept.restarted);
  EXPECT_EQ(kept.frame.status, TrackStatus::kKeypoints);
}

TEST(TrackingSession, ResetWaitsForAPoseAndInvalidFramesChangeNothing) {
  const Scene scene;
  TrackingSession session(scene.mesh, make_preset("klt_only"));
  EXPECT_THROW(session.initialize(scene.pose(0)), std::logic_error);
  EXPECT_THROW(session.tracker(), std::logic_error);
  session.set_camera(scene.camera);
  session.initialize(scene.pose(0));
  session.track({scene.visible(0), 0.0});
  const SessionResult invalid = session.track({cv::Mat(10, 10, CV_8UC3), 0.1});
  EXPECT_EQ(invalid.frame.status, TrackStatus::kInvalidInput);
  EXPECT_FALSE(invalid.has_pose());
  EXPECT_EQ(invalid.quality, 0.0);
  EXPECT_EQ(session.state(), TrackState::kTracking);
  EXPECT_EQ(session.statistics().invalid_frames, 1);
  session.reset();
  EXPECT_EQ(session.state(), TrackState::kWaitingForPose);
  EXPECT_EQ(session.track({scene.visible(1), 0.2}).frame.status, TrackStatus::kNotInitialized);
  Pose behind = scene.pose(0);
  behind.translation().z() = -1.0;
  EXPECT_THROW(session.initialize(behind), std::invalid_argument);
  EXPECT_THROW(TrackingSession(std::make_shared<Mesh>(), make_preset("paper")), std::invalid_argument);
}

}  // namespace
}  // namespace kct

namespace kct {
namespace {

TrackerParams quick_realtime() {
  TrackerParams params = make_preset("realtime");
  params.icosphere_subdivisions = 2;
  params.visibility_resolution_px = 128;
  params.visibility_cache_dir = "";
  return params;
}

/// The colour tests' scene: a red box over a blue-grey textured background (unlike the box).
struct ColourScene {
  std::shared_ptr<Mesh> mesh = red_box();
  Renderer renderer{mesh};
  PinholeCamera camera = test::make_camera();
  cv::Mat background = test::make_background(camera.size(), 5) * 0.5 + cv::Scalar(90, 70, 40);
  Pose start = test::make_pose(0.45);

  static std::shared_ptr<Mesh> red_box() {
    auto box = std::make_shared<Mesh>(test::make_box(0.12, 0.08, 0.06));
    box->base_color = cv::Vec3b(30, 40, 210);
    return box;
  }
};

/// Tracks the red box 8 frames at its start, each of which must end TRACKING; `stamp` is
/// advanced past them.
void track_start(TrackingSession& session, const ColourScene& scene, double& stamp) {
  session.set_camera(scene.camera);
  session.initialize(scene.start);
  for (int i = 0; i < 8; ++i, stamp += 0.033) {
    const SessionResult r = session.track(
        {test::render_frame(scene.renderer, scene.camera, scene.start, scene.background, 1.5, i), stamp});
    ASSERT_EQ(r.state, TrackState::kTracking) << i;
  }
}

/// A re-acquisition that took the object where it is: within 1 cm and 3 deg of `truth`, the
/// tolerance of every re-acquisition test here.
void expect_found_at(const SessionResult& r, const Pose& truth) {
  EXPECT_LT(translation_error(r.frame.object_to_camera, truth), 0.01);
  EXPECT_LT(rotation_error_deg(r.frame.object_to_camera, truth), 3.0);
}

/// What a correcting check (rotation_check, texture_check) did while an object came back.
struct CheckRun {
  SessionResult first;       ///< the first shown frame's result
  SessionResult last;        ///< the last frame's result
  bool lost = false;         ///< some shown frame ended LOST
  int first_corrected = -1;  ///< first shown frame the check corrected (-1: none)
  int corrections = 0;       ///< shown frames it corrected
};

/// Tracks 8 frames of the object at `start`, one frame of the bare background (KLT fails: the
/// checks' window opens), then 8 frames of it at `truth`, counting the frames whose `corrected`
/// flag is set.
CheckRun hide_and_show(TrackingSession& session, const Renderer& renderer, const PinholeCamera& camera,
                       const cv::Mat& background, const Pose& start, const Pose& truth,
                       bool SessionResult::*corrected) {
  session.set_camera(camera);
  session.initialize(start);
  double stamp = 0.0;
  for (int i = 0; i < 8; ++i, stamp += 0.033)
    session.track({test::render_frame(renderer, camera, start, background, 1.5, i), stamp});
  session.track({background.clone(), stamp});
  stamp += 0.033;
  CheckRun run;
  for (int i = 0; i < 8; ++i, stamp += 0.033) {
    run.last = session.track({test::render_frame(renderer, camera, truth, background, 1.5, 20 + i), stamp});
    if (i == 0) run.first = run.last;
    run.lost = run.lost || run.last.state == TrackState::kLost;
    if (run.last.*corrected && run.first_corrected < 0) run.first_corrected = i;
    run.corrections += run.last.*corrected ? 1 : 0;
  }
  return run;
}

/// The colour search of the realtime preset (color_search): a red box over a textured blue-grey
/// background is hidden, then shown again 12 cm to the side and 8 deg turned, far outside the
/// local refinement's reach; the session must find it again within 10 frames.
TEST(TrackingSession, ColourSearchReacquiresAnObjectThatReappearsFarAway) {
  const ColourScene scene;
  const auto& mesh = scene.mesh;
  const Renderer& renderer = scene.renderer;
  const PinholeCamera& camera = scene.camera;
  const cv::Mat& background = scene.background;
  const Pose& start = scene.start;
  const Pose away = test::move(start, 8.0, {0.2, 1.0, 0.3}, {0.12, 0.04, 0.0});
  TrackerParams params = quick_realtime();
  params.feature_relocalization = false;  // the colour search alone (its features find it too)
  for (const bool with_search : {false, true}) {
    params.color_search = with_search;
    TrackingSession session(mesh, params);
    session.set_camera(camera);
    session.initialize(start);
    double stamp = 0.0;
    for (int i = 0; i < 8; ++i, stamp += 0.033) {
      const SessionResult r =
          session.track({test::render_frame(renderer, camera, start, background, 1.5, i), stamp});
      ASSERT_EQ(r.state, TrackState::kTracking) << i;
    }
    for (int i = 0; i < 12; ++i, stamp += 0.033)
      session.track({background.clone(), stamp});
    ASSERT_EQ(session.state(), TrackState::kLost) << "the hidden object must be declared lost";
    bool back = false;
    for (int i = 0; i < 10 && !back; ++i, stamp += 0.033) {
      const SessionResult r =
          session.track({test::render_frame(renderer, camera, away, background, 1.5, 50 + i), stamp});
      back = r.state == TrackState::kTracking &&
             translation_error(r.frame.object_to_camera, away) < 0.01 &&
             rotation_error_deg(r.frame.object_to_camera, away) < 3.0;
    }
    // Without the search the refinement around the last good pose cannot reach it.
    EXPECT_EQ(back, with_search) << (with_search ? "not re-acquired within 10 frames"
                                                 : "found without the colour search?");
  }
}

/// set_record_hypotheses: the red box of the test above is hidden until lost and shown again
/// 12 cm away. Recording lists every hypothesis the re-acquiring searches refined, exactly one
/// chosen per search, the chosen one of the best colour contrast among those in reach, and one of
/// them on the box; and it changes nothing of the tracking (the same poses with it off, when
/// nothing is listed).
TEST(TrackingSession, RecordedHypothesesAreWhatTheSearchChoseFrom) {
  const ColourScene scene;
  const Pose away = test::move(scene.start, 8.0, {0.2, 1.0, 0.3}, {0.12, 0.04, 0.0});
  TrackerParams params = quick_realtime();
  params.feature_relocalization = false;
  std::vector<std::vector<SessionResult>> runs;
  for (const bool record : {false, true}) {
    TrackingSession session(scene.mesh, params);
    session.set_camera(scene.camera);
    session.set_record_hypotheses(record);
    session.initialize(scene.start);
    std::vector<SessionResult> results;
    double stamp = 0.0;
    for (int i = 0; i < 8; ++i, stamp += 0.033)
      results.push_back(session.track(
          {test::render_frame(scene.renderer, scene.camera, scene.start, scene.background, 1.5, i), stamp}));
    for (int i = 0; i < 12; ++i, stamp += 0.033) results.push_back(session.track({scene.background.clone(), stamp}));
    for (int i = 0; i < 6; ++i, stamp += 0.033)
      results.push_back(session.track(
          {test::render_frame(scene.renderer, scene.camera, away, scene.background, 1.5, 50 + i), stamp}));
    runs.push_back(results);
  }
  const auto& plain = runs[0];
  const auto& recorded = runs[1];
  ASSERT_EQ(plain.size(), recorded.size());
  int searches = 0, on_the_box = 0;
  for (std::size_t i = 0; i < recorded.size(); ++i) {
    EXPECT_TRUE(plain[i].hypotheses.empty()) << i;
    EXPECT_TRUE(plain[i].frame.object_to_camera.isApprox(recorded[i].frame.object_to_camera, 1e-12))
        << "recording changed the track at frame " << i;
    EXPECT_EQ(plain[i].state, recorded[i].state) << i;
    const std::vector<HypothesisRecord>& h = recorded[i].hypotheses;
    if (h.empty()) continue;
    EXPECT_EQ(recorded[i].reacquiring, h.front().reacquiring) << i;
    // One search's hypotheses: the last good pose first, then the others (a frame may hold two
    // searches; each has its own chosen one).
    int chosen = 0;
    double best_in_reach = -1e9;
    const HypothesisRecord* pick = nullptr;
    for (const HypothesisRecord& r : h) {
      chosen += r.chosen ? 1 : 0;
      if (r.chosen) pick = &r;
      if (r.in_reach) best_in_reach = std::max(best_in_reach, r.contrast);
      if (translation_error(r.object_to_camera, away) < 0.01 &&
          rotation_error_deg(r.object_to_camera, away) < 3.0)
        ++on_the_box;
    }
    ASSERT_GE(chosen, 1) << i;
    ++searches;
    if (chosen == 1) {
      EXPECT_DOUBLE_EQ(pick->contrast, best_in_reach) << i;
    }
  }
  EXPECT_GT(searches, 0) << "no search recorded: the test shows nothing";
  EXPECT_GT(on_the_box, 0) << "no recorded hypothesis on the box that came back";
}

/// color_search_refined: the red box is hidden until lost and shown again 12 cm away. With all
/// placements and turns refined a search holds up to 2 + 3 x 7 hypotheses; with 3 kept, at most
/// 2 + 3 (a frame may hold two searches), and the box is still found again within 10 frames.
TEST(TrackingSession, ColourSearchRefinesOnlyTheBestPlacements) {
  const ColourScene scene;
  const Pose away = test::move(scene.start, 8.0, {0.2, 1.0, 0.3}, {0.12, 0.04, 0.0});
  TrackerParams params = quick_realtime();
  params.feature_relocalization = false;
  ASSERT_EQ(params.color_search_placements, 3);
  ASSERT_GT(params.color_search_rotation_deg, 0.0);
  for (const int refined : {0, 3}) {
    SCOPED_TRACE("color_search_refined " + std::to_string(refined));
    params.color_search_refined = refined;
    TrackingSession session(scene.mesh, params);
    session.set_camera(scene.camera);
    session.set_record_hypotheses(true);
    session.initialize(scene.start);
    double stamp = 0.0;
    for (int i = 0; i < 8; ++i, stamp += 0.033)
      session.track({test::render_frame(scene.renderer, scene.camera, scene.start, scene.background, 1.5, i), stamp});
    for (int i = 0; i < 12; ++i, stamp += 0.033) session.track({scene.background.clone(), stamp});
    ASSERT_EQ(session.state(), TrackState::kLost);
    std::size_t most = 0;
    bool back = false;
    for (int i = 0; i < 10 && !back; ++i, stamp += 0.033) {
      const SessionResult r = session.track(
          {test::render_frame(scene.renderer, scene.camera, away, scene.background, 1.5, 50 + i), stamp});
      most = std::max(most, r.hypotheses.size());
      back = r.state == TrackState::kTracking && translation_error(r.frame.object_to_camera, away) < 0.01 &&
             rotation_error_deg(r.frame.object_to_camera, away) < 3.0;
    }
    EXPECT_TRUE(back) << "not re-acquired within 10 frames";
    if (refined == 0) {
      EXPECT_GT(most, 2u * (3 + 2)) << "the search refined no more than it would keep: the test shows nothing";
    } else {
      EXPECT_LE(most, 2u * (3 + 2));
    }
  }
}

/// color_search_reach_diameters: the red box is hidden until the session declares it lost, then
/// comes back 2 cm from where it was, its middle covered by a bar, while a whole twin stands 17 cm
/// away on the other side (the better colour match). Searching the whole frame takes the twin;
/// with a reach (here 0.05 diameters a frame, so that the twin is out of it after the frames
/// hidden) the box is taken.
TEST(TrackingSession, AReachKeepsReacquisitionOffAFarTwin) {
  const ColourScene scene;
  const Pose near = test::move(scene.start, 0.0, {0.0, 0.0, 1.0}, {-0.02, 0.0, 0.0});
  const Pose twin = test::move(scene.start, 0.0, {0.0, 0.0, 1.0}, {0.17, 0.0, 0.0});
  const Eigen::Vector3d centre = scene.mesh->bounding_box_center();
  const auto shown = [&](int noise_seed) {
    cv::Mat frame = test::render_frame(scene.renderer, scene.camera, twin, scene.background, 1.5, noise_seed);
    const cv::Mat near_frame =
        test::render_frame(scene.renderer, scene.camera, near, scene.background, 1.5, noise_seed);
    near_frame.copyTo(frame, scene.renderer.render(near, scene.camera).mask());
    const Eigen::Vector2d c = scene.camera.project(near * centre);
    cv::rectangle(frame, cv::Point2d(c.x() - 90, c.y() - 30), cv::Point2d(c.x() + 90, c.y() + 30),
                  cv::Scalar(90, 70, 40), cv::FILLED);
    return frame;
  };
  TrackerParams params = quick_realtime();
  params.feature_relocalization = false;  // the colour search's reach (the features': below)
  for (const double reach : {0.0, 0.05}) {
    params.color_search_reach_diameters = reach;
    TrackingSession session(scene.mesh, params);
    session.set_camera(scene.camera);
    session.initialize(scene.start);
    double stamp = 0.0;
    for (int i = 0; i < 8; ++i, stamp += 0.033)
      ASSERT_EQ(session.track({test::render_frame(scene.renderer, scene.camera, scene.start,
                                                  scene.background, 1.5, i),
                               stamp}).state,
                TrackState::kTracking) << i;
    for (int i = 0; i < 15 && session.state() != TrackState::kLost; ++i, stamp += 0.033)
      session.track({scene.background.clone(), stamp});
    ASSERT_EQ(session.state(), TrackState::kLost) << "the hidden box must be declared lost";
    Pose taken = scene.start;
    bool reacquired = false;
    for (int i = 0; i < 10 && !reacquired; ++i, stamp += 0.033) {
      const SessionResult r = session.track({shown(50 + i), stamp});
      reacquired = r.state == TrackState::kTracking;
      taken = r.frame.object_to_camera;
    }
    ASSERT_TRUE(reacquired) << "reach " << reach;
    // Tolerance: 2 cm (the bar hides part of the near box's outline); the two are 19 cm apart.
    if (reach > 0.0)
      EXPECT_LT(translation_error(taken, near), 0.02);
    else
      EXPECT_LT(translation_error(taken, twin), 0.02) << "the twin must win without a reach: no test";
  }
}

/// extrapolated_search_ratio: the red box jumps 18 cm sideways between two frames (too far for
/// KLT and for the shift search). The refined pose of the jump frame has lost the colours; with
/// the ratio the colour search runs on that frame and finds the box there, without it the track
/// is not searched on that frame (the session has not declared the loss yet).
TEST(TrackingSession, AJumpIsSearchedForOnTheFrameItHappens) {
  const ColourScene scene;
  const Pose away = test::move(scene.start, 8.0, {0.2, 1.0, 0.3}, {-0.15, 0.1, 0.0});
  TrackerParams params = quick_realtime();
  ASSERT_GT(params.extrapolated_search_ratio, 0.0) << "realtime searches at once";
  // The jump (1.2 diameters in a frame) is beyond what a hand moves an object in a frame, which
  // the reach assumes: searched over the whole frame here.
  params.color_search_reach_diameters = 0.0;
  // The colour search alone: the relocalizer's features find the jump too (measured: 3 mm off).
  params.feature_relocalization = false;
  for (const double ratio : {0.0, params.extrapolated_search_ratio}) {
    params.extrapolated_search_ratio = ratio;
    TrackingSession session(scene.mesh, params);
    double stamp = 0.0;
    ASSERT_NO_FATAL_FAILURE(track_start(session, scene, stamp));
    const SessionResult jump = session.track(
        {test::render_frame(scene.renderer, scene.camera, away, scene.background, 1.5, 30), stamp});
    EXPECT_FALSE(jump.reacquiring) << "the session was not lost before the jump";
    if (ratio == 0.0) {
      EXPECT_FALSE(jump.searched);
      EXPECT_GT(translation_error(jump.frame.object_to_camera, away), 0.05) << "no jump: no test";
    } else {
      EXPECT_TRUE(jump.searched);
      EXPECT_EQ(jump.frame.status, TrackStatus::kReacquired);
      expect_found_at(jump, away);
    }
  }
}

/// extrapolated_accept_margin: the same jump, but the jump frame's box is washed out towards
/// grey (blur and glare after a jerk): its right placement keeps less of the colour contrast than
/// color_accept_ratio asks, yet far more than the held pose, which sits on the background. Without
/// the margin the find is not taken on that frame; with it, it is.
TEST(TrackingSession, AWashedOutJumpIsTakenWhenItBeatsTheHeldPoseByTheMargin) {
  const ColourScene scene;
  const Pose away = test::move(scene.start, 8.0, {0.2, 1.0, 0.3}, {-0.15, 0.1, 0.0});
  TrackerParams params = quick_realtime();
  params.color_search_reach_diameters = 0.0;  // as AJumpIsSearchedForOnTheFrameItHappens
  params.feature_relocalization = false;
  const double realtime_margin = params.extrapolated_accept_margin;
  ASSERT_GT(realtime_margin, 0.0) << "realtime takes such finds";
  // The jump frame: the box blended a fifth of the way to the background's mean grey (its
  // right placement then keeps ~0.65 x the contrast level: above the margin's floor of 0.5,
  // below color_accept_ratio 0.8).
  const cv::Mat sharp = test::render_frame(scene.renderer, scene.camera, away, scene.background, 1.5, 30);
  const cv::Mat mask = scene.renderer.render_silhouette(away, scene.camera);
  cv::Mat washed = sharp.clone();
  cv::Mat grey(sharp.size(), sharp.type(), cv::mean(scene.background));
  cv::Mat blend;
  cv::addWeighted(sharp, 0.8, grey, 0.2, 0.0, blend);
  blend.copyTo(washed, mask);
  for (const double margin : {0.0, realtime_margin}) {
    params.extrapolated_accept_margin = margin;
    TrackingSession session(scene.mesh, params);
    double stamp = 0.0;
    ASSERT_NO_FATAL_FAILURE(track_start(session, scene, stamp));
    const double level = session.monitor().color_level();
    const SessionResult jump = session.track({washed, stamp});
    ASSERT_EQ(jump.frame.status == TrackStatus::kReacquired, jump.searched);
    if (margin == 0.0) {
      EXPECT_FALSE(jump.searched) << "the washed-out box passes color_accept_ratio: no test";
      EXPECT_GT(translation_error(jump.frame.object_to_camera, away), 0.05) << "no jump: no test";
    } else {
      EXPECT_TRUE(jump.searched);
      expect_found_at(jump, away);
      EXPECT_LT(jump.color.contrast, params.color_accept_ratio * level)
          << "taken by the accept ratio, not the margin: no test";
    }
  }
}

/// tracked_search_ratio: the red box jumps 18 cm sideways and the jump frame is not searched
/// (extrapolated_search_ratio off) and its keypoints, laid at the held pose, are kept
/// (drop_unconfirmed_anchors off): they lie on the textured background, which KLT then tracks
/// perfectly while the box is elsewhere. With the ratio the colour search runs on such a
/// KLT-tracked frame and its find, beating the held pose's colours, replaces it before the loss
/// is declared; without it the held pose stays on the background.
TEST(TrackingSession, ATrackHeldOnTheBackgroundIsSearchedForBeforeTheLoss) {
  const ColourScene scene;
  const Pose away = test::move(scene.start, 8.0, {0.2, 1.0, 0.3}, {-0.15, 0.1, 0.0});
  TrackerParams params = quick_realtime();
  ASSERT_GT(params.tracked_search_ratio, 0.0) << "realtime searches tracked frames";
  params.extrapolated_search_ratio = 0.0;
  params.drop_unconfirmed_anchors = false;
  params.color_search_reach_diameters = 0.0;  // a jump beyond the reach, as in the test above
  // The held pose's surface disagrees: the keyframe's features would find the box (another rule).
  params.relocalization_below_correlation = 0.0;
  for (const double ratio : {0.0, params.tracked_search_ratio}) {
    params.tracked_search_ratio = ratio;
    TrackingSession session(scene.mesh, params);
    double stamp = 0.0;
    ASSERT_NO_FATAL_FAILURE(track_start(session, scene, stamp));
    const SessionResult jump = session.track(
        {test::render_frame(scene.renderer, scene.camera, away, scene.background, 1.5, 30), stamp});
    stamp += 0.033;
    ASSERT_FALSE(jump.searched) << "the jump frame is not searched here";
    ASSERT_GT(translation_error(jump.frame.object_to_camera, away), 0.05) << "no jump: no test";
    // The next two frames, before the loss can be declared (lost_after_bad_frames = 3).
    int keypoint_frames = 0;
    SessionResult found;
    for (int i = 0; i < 2 && !found.searched; ++i, stamp += 0.033) {
      const SessionResult r = session.track(
          {test::render_frame(scene.renderer, scene.camera, away, scene.background, 1.5, 31 + i), stamp});
      EXPECT_FALSE(r.reacquiring) << i;
      // A searched frame was KLT-tracked: only such frames are searched here.
      if (r.frame.keypoints.success || r.searched) ++keypoint_frames;
      found = r;
    }
    EXPECT_GT(keypoint_frames, 0) << "KLT must hold the background: no test";
    if (ratio == 0.0) {
      EXPECT_FALSE(found.searched);
      EXPECT_GT(translation_error(found.frame.object_to_camera, away), 0.05);
    } else {
      ASSERT_TRUE(found.searched);
      EXPECT_EQ(found.frame.status, TrackStatus::kReacquired);
      expect_found_at(found, away);
    }
  }
}

/// feature_relocalization: a textured box is hidden, then shown again 12 cm to the side and 8 deg
/// turned (far outside the refinement's reach); with the colour search off, only the keyframe
/// features of the initial pose can find it: re-acquired within 10 frames with, never without,
/// whether the features are matched on every frame or only while lost
/// (relocalization_while_tracking); and not while it is farther than it could have gone
/// (color_search_reach_diameters 0.01: 4 mm a frame, 2-4 cm over the frames here).
TEST(TrackingSession, FeatureRelocalizationReacquiresATexturedObjectFarAway) {
  const Scene scene;
  const Pose start = test::make_pose(0.45);
  const Pose away = test::move(start, 8.0, {0.2, 1.0, 0.3}, {0.12, 0.04, 0.0});
  TrackerParams params = quick_realtime();
  params.color_search = false;
  struct Mode {
    bool features, while_tracking;
    double reach_diameters;
  };
  const double reach = params.color_search_reach_diameters;
  for (const Mode mode : {Mode{false, true, reach}, Mode{true, true, reach},
                          Mode{true, false, reach}, Mode{true, false, 0.01}}) {
    const bool with_features = mode.features && mode.reach_diameters > 0.05;
    SCOPED_TRACE(!mode.features ? "off"
                 : mode.reach_diameters <= 0.05 ? "out of reach"
                 : mode.while_tracking          ? "every frame"
                                                : "while lost");
    params.feature_relocalization = mode.features;
    params.relocalization_while_tracking = mode.while_tracking;
    params.color_search_reach_diameters = mode.reach_diameters;
    TrackingSession session(scene.mesh, params);
    session.set_camera(scene.camera);
    session.initialize(start);
    double stamp = 0.0;
    for (int i = 0; i < 6; ++i, stamp += 0.033) {
      const SessionResult r = session.track(
          {test::render_frame(scene.renderer, scene.camera, start, scene.background, 1.5, i), stamp});
      ASSERT_EQ(r.state, TrackState::kTracking) << i;
      EXPECT_FALSE(r.relocalized) << "the features agree with a held track: nothing to replace";
    }
    for (int i = 0; i < 12; ++i, stamp += 0.033) session.track({scene.hidden(i), stamp});
    ASSERT_EQ(session.state(), TrackState::kLost) << "the hidden object must be declared lost";
    bool back = false, relocalized = false;
    for (int i = 0; i < 10 && !back; ++i, stamp += 0.033) {
      const SessionResult r = session.track(
          {test::render_frame(scene.renderer, scene.camera, away, scene.background, 1.5, 50 + i), stamp});
      relocalized = relocalized || r.relocalized;
      // Tolerances: 5 mm and 2 deg for a 12 cm box at 0.45 m.
      back = r.state == TrackState::kTracking &&
             translation_error(r.frame.object_to_camera, away) < 0.005 &&
             rotation_error_deg(r.frame.object_to_camera, away) < 2.0;
    }
    EXPECT_EQ(back, with_features) << (with_features ? "not re-acquired within 10 frames"
                                                     : "found without the features, or out of reach?");
    EXPECT_EQ(relocalized, with_features);
  }
}

/// relocalization_interval_frames: the textured box of the test above, hidden until lost and
/// shown again far away, is relocalized by its features only on the first lost frame and every
/// interval-th after it: found within 10 frames at intervals 1 and 2, never at 1000 (the first
/// lost frame showed nothing).
TEST(TrackingSession, FeaturesAreMatchedOnEveryIntervalthLostFrame) {
  const Scene scene;
  const Pose start = test::make_pose(0.45);
  const Pose away = test::move(start, 8.0, {0.2, 1.0, 0.3}, {0.12, 0.04, 0.0});
  TrackerParams params = quick_realtime();
  params.color_search = false;  // the features alone
  params.feature_relocalization = true;
  params.relocalization_while_tracking = false;
  for (const int interval : {1, 2, 1000}) {
    SCOPED_TRACE("relocalization_interval_frames " + std::to_string(interval));
    params.relocalization_interval_frames = interval;
    TrackingSession session(scene.mesh, params);
    session.set_camera(scene.camera);
    session.initialize(start);
    double stamp = 0.0;
    for (int i = 0; i < 6; ++i, stamp += 0.033)
      session.track({test::render_frame(scene.renderer, scene.camera, start, scene.background, 1.5, i), stamp});
    int reacquiring = 0;  // frames in a row that re-acquired, as the session counts them
    const auto counted = [&](const SessionResult& r) {
      reacquiring = r.reacquiring ? reacquiring + 1 : 0;
      if (r.relocalized) {
        EXPECT_EQ((reacquiring - 1) % interval, 0) << "relocalized off the interval";
      }
    };
    for (int i = 0; i < 12; ++i, stamp += 0.033) counted(session.track({scene.hidden(i), stamp}));
    ASSERT_EQ(session.state(), TrackState::kLost);
    bool back = false, relocalized = false;
    for (int i = 0; i < 10 && !back; ++i, stamp += 0.033) {
      const SessionResult r = session.track(
          {test::render_frame(scene.renderer, scene.camera, away, scene.background, 1.5, 50 + i), stamp});
      counted(r);
      relocalized = relocalized || r.relocalized;
      back = r.state == TrackState::kTracking && translation_error(r.frame.object_to_camera, away) < 0.005 &&
             rotation_error_deg(r.frame.object_to_camera, away) < 2.0;
    }
    EXPECT_EQ(back, interval < 1000);
    EXPECT_EQ(relocalized, interval < 1000);
  }
}

/// color_confirm_ratio: the object comes back far away with its colours washed out (as under
/// blur or a partial occlusion), so that the best placement's contrast stays below
/// color_accept_ratio x the learned level. Without confirmation the session never
/// takes it; with it, the placement is taken once two frames agree, and not on the first frame.
TEST(TrackingSession, WeakColourPlacementIsTakenWhenTwoFramesAgree) {
  const ColourScene scene;
  const auto& mesh = scene.mesh;
  const Renderer& renderer = scene.renderer;
  const PinholeCamera& camera = scene.camera;
  const cv::Mat& background = scene.background;
  const Pose& start = scene.start;
  const Pose away = test::move(start, 8.0, {0.2, 1.0, 0.3}, {-0.16, 0.03, 0.0});
  // The object's pixels blended 10 % with the background behind them (contrast about 0.85 x
  // the learned level, measured), and an acceptance ratio above that.
  const auto washed_frame = [&](int seed) {
    const cv::Mat mask = renderer.render(away, camera).mask();
    cv::Mat frame = test::render_frame(renderer, camera, away, background, 1.5, seed), blended;
    cv::addWeighted(frame, 0.9, background, 0.1, 0.0, blended);
    blended.copyTo(frame, mask);
    return frame;
  };
  TrackerParams params = quick_realtime();
  params.feature_relocalization = false;  // the colour search alone (its features find it too)
  ASSERT_GT(params.color_confirm_ratio, 0.0) << "realtime confirms weak placements";
  params.color_accept_ratio = 0.95;
  // The lost frames refined around the last good pose: tracked on instead (track_while_lost),
  // they are KLT failures whose extrapolated-search find is taken when it beats the held pose
  // (extrapolated_accept_margin), another rule than the one tested here.
  params.track_while_lost = false;
  for (const double confirm : {0.0, params.color_confirm_ratio}) {
    params.color_confirm_ratio = confirm;
    TrackingSession session(mesh, params);
    session.set_camera(camera);
    session.initialize(start);
    double stamp = 0.0;
    for (int i = 0; i < 8; ++i, stamp += 0.033)
      session.track({test::render_frame(renderer, camera, start, background, 1.5, i), stamp});
    for (int i = 0; i < 12; ++i, stamp += 0.033) session.track({background.clone(), stamp});
    ASSERT_EQ(session.state(), TrackState::kLost);
    int found_at = -1;
    for (int i = 0; i < 10 && found_at < 0; ++i, stamp += 0.033) {
      const SessionResult r = session.track({washed_frame(50 + i), stamp});
      if (translation_error(r.frame.object_to_camera, away) < 0.01 &&
          rotation_error_deg(r.frame.object_to_camera, away) < 3.0)
        found_at = i;
    }
    if (confirm == 0.0) {
      EXPECT_EQ(found_at, -1) << "the washed-out placement passed color_accept_ratio: no test";
    } else {
      EXPECT_GE(found_at, 1) << "taken on the first frame back: not confirmed";
      EXPECT_LE(found_at, 3) << "not re-acquired within 4 frames (-1: never)";
    }
  }
}

/// rotation_check: the red box vanishes for a frame (KLT fails) and comes back at the same place
/// turned 20 deg about the camera's x axis. Without the check the track settles on a pose 20 deg
/// off that every cue accepts (reported good); with it a turned hypothesis wins on two
/// consecutive frames and replaces it. Shown unturned, nothing is replaced.
TEST(TrackingSession, RotationCheckCorrectsAWrongRotationTheTrackHolds) {
  const ColourScene scene;  // the box is centred at its origin: test::move turns it in place
  ASSERT_GT(make_preset("realtime").rotation_check_deg, 0.0) << "realtime checks rotations";
  for (const double turn_deg : {0.0, 20.0})
    for (const bool check : {false, true}) {
      TrackerParams params = quick_realtime();
      if (!check) params.rotation_check_deg = 0.0;
      // The rotation check alone: the relocalizer's features find the turned box too (measured:
      // 0.2 deg off without the check).
      params.feature_relocalization = false;
      TrackingSession session(scene.mesh, params);
      const Pose truth = test::move(scene.start, turn_deg, Eigen::Vector3d::UnitX(), Eigen::Vector3d::Zero());
      const CheckRun run = hide_and_show(session, scene.renderer, scene.camera, scene.background, scene.start,
                                         truth, &SessionResult::rotation_corrected);
      const SessionResult& r = run.last;
      const int first_corrected = run.first_corrected, corrections = run.corrections;
      const std::string what = "turn " + std::to_string(turn_deg) + (check ? " with" : " without") + " the check";
      ASSERT_EQ(r.state, TrackState::kTracking) << what;
      EXPECT_TRUE(r.good) << what;
      // Tolerances for a 12 cm box at 0.45 m: 2 deg and 5 mm when right; the wrong hold is the
      // turn itself (measured: 20 deg).
      if (turn_deg == 0.0 || check) {
        EXPECT_LT(rotation_error_deg(r.frame.object_to_camera, truth), 2.0) << what;
        EXPECT_LT(translation_error(r.frame.object_to_camera, truth), 0.005) << what;
      } else {
        EXPECT_GT(rotation_error_deg(r.frame.object_to_camera, truth), 10.0)
            << "the turned box was found without the check: the test shows nothing";
      }
      if (turn_deg == 0.0 || !check) {
        EXPECT_EQ(corrections, 0) << what;
      } else {
        EXPECT_GE(first_corrected, 1) << "corrected on the first frame: not confirmed (-1: never)";
        EXPECT_EQ(corrections, 1) << what;
      }
    }
}

/// check_while_lost: the red box is hidden for a frame and comes back 20 deg turned, but the
/// monitor keeps the session LOST (every frame bad but the first few: the energy ratio alone,
/// good only at or above its level) and the colour search takes nothing (it must beat the colour
/// level itself, with no confirmation by a second frame), so each lost frame's pose is the
/// pipeline's. With the checks while lost, texture_check scores every such frame's pose against
/// the learned surface (the correlation it reports); without them none is scored.
TEST(TrackingSession, WhileLostTheHeldPoseIsCheckedOnlyWhenAsked) {
  const ColourScene scene;
  const Pose truth = test::move(scene.start, 20.0, Eigen::Vector3d::UnitX(), Eigen::Vector3d::Zero());
  ASSERT_FALSE(make_preset("realtime").check_while_lost) << "realtime does not check while lost";
  TrackQualityParams quality;
  quality.min_quality = 1.0;
  quality.energy_weight = 1.0;
  for (const bool check : {true, false}) {
    TrackerParams params = quick_realtime();
    params.check_while_lost = check;
    params.feature_relocalization = false;
    params.color_accept_ratio = 1.0;
    params.color_confirm_ratio = 0.0;
    TrackingSession session(scene.mesh, params, quality);
    session.set_camera(scene.camera);
    session.initialize(scene.start);
    int pipeline_frames = 0, scored = 0;
    for (int i = 0; i < 17; ++i) {
      const cv::Mat image =
          i == 8 ? scene.background.clone()
                 : test::render_frame(scene.renderer, scene.camera, i < 8 ? scene.start : truth,
                                      scene.background, 1.5, i);
      const SessionResult r = session.track({image, 0.033 * i});
      if (!r.reacquiring || r.searched) continue;
      ASSERT_TRUE(r.frame.status == TrackStatus::kKeypoints || r.frame.status == TrackStatus::kExtrapolated)
          << i;
      ++pipeline_frames;
      scored += std::isfinite(r.texture_correlation) ? 1 : 0;
    }
    const std::string what = check ? "with the checks while lost" : "without them";
    ASSERT_GE(pipeline_frames, 4) << what << ": the session must be lost on the pipeline's poses";
    EXPECT_EQ(scored, check ? pipeline_frames : 0) << what;
  }
}

/// The texture tests' scene: a randomly textured 10 cm cube (centred at its origin) over the
/// colour tests' background.
struct CubeScene {
  std::shared_ptr<Mesh> cube = std::make_shared<Mesh>(test::make_box(0.1, 0.1, 0.1));
  Renderer renderer{cube};
  PinholeCamera camera = test::make_camera();
  cv::Mat background = test::make_background(camera.size(), 5) * 0.5 + cv::Scalar(90, 70, 40);
  Pose start = test::make_pose(0.45);
};

/// texture_check: a textured cube vanishes for a frame (KLT fails) and comes back at the same
/// place turned 90 deg about its own z axis: the same outline and colours, another face
/// pattern. Without the check the track holds the unturned pose (reported good); with it the
/// learned surface colours find the turn on two consecutive frames and it replaces the pose.
TEST(TrackingSession, TextureCheckFindsATurnAboutTheObjectsAxis) {
  const CubeScene scene;
  const Pose& start = scene.start;
  ASSERT_GT(make_preset("realtime").texture_check_margin, 0.0) << "realtime checks the texture";
  for (const double turn_deg : {0.0, 90.0})
    for (const bool check : {false, true}) {
      TrackerParams params = quick_realtime();
      if (!check) params.texture_check_margin = 0.0;
      TrackingSession session(scene.cube, params);
      Pose truth = start;
      truth.linear() = start.linear() * Eigen::AngleAxisd(turn_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      const CheckRun run = hide_and_show(session, scene.renderer, scene.camera, scene.background,
                                         start, truth, &SessionResult::texture_corrected);
      const SessionResult& r = run.last;
      const int first_corrected = run.first_corrected, corrections = run.corrections;
      const std::string what = "turn " + std::to_string(turn_deg) + (check ? " with" : " without") + " the check";
      ASSERT_EQ(r.state, TrackState::kTracking) << what;
      EXPECT_TRUE(r.good) << what;
      // Tolerances for a 10 cm cube at 0.45 m: 4 deg (measured 2.7 unturned, with or without the
      // check: the cube's outline fixes its rotation loosely) and 5 mm when right; the wrong hold
      // is the turn itself.
      if (turn_deg == 0.0 || check) {
        EXPECT_LT(rotation_error_deg(r.frame.object_to_camera, truth), 4.0) << what;
        EXPECT_LT(translation_error(r.frame.object_to_camera, truth), 0.005) << what;
      } else {
        EXPECT_GT(rotation_error_deg(r.frame.object_to_camera, truth), 45.0)
            << "the turned cube was found without the check: the test shows nothing";
      }
      if (!check) {
        EXPECT_EQ(corrections, 0) << what;
      } else if (turn_deg > 0.0) {
        EXPECT_GE(first_corrected, 1) << "corrected on the first frame: not confirmed (-1: never)";
        EXPECT_EQ(corrections, 1) << what;
      }
      // Unturned, the check may still correct the pose the refinement settles on after the
      // empty frame (measured: once, a 10 deg turn about the cube's x axis); the pose is then
      // right, as asserted above.
      EXPECT_LE(corrections, 1) << what;
    }
}

/// The checks that correct a held pose by itself off: the texture check's turns (a margin no
/// correlation reaches), the surface's shifts and alignment, rotation_check's turns.
void without_pose_corrections(TrackerParams& params) {
  params.texture_check_margin = 2.0;
  params.texture_align_below = 0.0;
  params.texture_shift_search_below = 0.0;
  params.rotation_check_deg = 0.0;
}

/// relocalization_below_correlation: the textured box vanishes for a frame (KLT fails) and comes
/// back turned 180 deg about its own axis nearest the line of sight: the same outline (the box is
/// symmetric), other faces' patterns. With the checks that could find the turn off (the texture
/// check's turns need a margin no correlation reaches; no alignment, shift or rotation check),
/// the track holds the unturned pose, whose surface does not correlate. In doubt by that alone,
/// the keyframe's features are matched on the first frame back and their pose (the turn)
/// replaces the held one: never lost. With the rule off the track is held about 175 deg off
/// until it is declared lost (the features then re-acquire it).
TEST(TrackingSession, ATrackWhoseSurfaceDisagreesIsRelocalizedByFeatures) {
  const Scene scene;
  const Pose start = test::make_pose(0.45);
  ASSERT_GT(make_preset("realtime").relocalization_below_correlation, 0.0) << "realtime doubts such tracks";
  const Eigen::Vector3d view = start.translation().normalized();  // the box is centred at its origin
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::abs(start.linear().col(k).dot(view)) > std::abs(start.linear().col(axis).dot(view))) axis = k;
  Pose truth = start;
  truth.linear() = start.linear() * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::Unit(axis)).toRotationMatrix();
  for (const bool doubt : {false, true}) {
    SCOPED_TRACE(doubt ? "with the rule" : "without the rule");
    TrackerParams params = quick_realtime();
    without_pose_corrections(params);
    params.relocalization_below_correlation = doubt ? make_preset("realtime").relocalization_below_correlation : 0.0;
    TrackingSession session(scene.mesh, params);
    const CheckRun run = hide_and_show(session, scene.renderer, scene.camera, scene.background, start,
                                       truth, &SessionResult::relocalized);
    // Tolerances: 5 mm and 2 deg for a 12 cm box at 0.45 m, as the relocalization test's.
    const Pose& first = run.first.frame.object_to_camera;
    if (doubt) {
      EXPECT_TRUE(run.first.relocalized) << "not relocalized on the first frame back";
      EXPECT_LT(rotation_error_deg(first, truth), 2.0);
      EXPECT_LT(translation_error(first, truth), 0.005);
      EXPECT_FALSE(run.lost);
    } else {
      EXPECT_FALSE(run.first.relocalized);
      EXPECT_GT(rotation_error_deg(first, truth), 90.0)
          << "the turned box was found without the rule: the test shows nothing";
      EXPECT_TRUE(run.lost) << "the wrong hold was never declared lost";
    }
    EXPECT_LT(rotation_error_deg(run.last.frame.object_to_camera, truth), 2.0);
    EXPECT_LT(translation_error(run.last.frame.object_to_camera, truth), 0.005);
  }
}

/// relocalization_doubt_whole_frame: the textured box vanishes for a frame and comes back 18 cm
/// away. KLT's anchors, laid on the background on the empty frame, hold the old place, whose
/// surface does not correlate; the other checks that could find the box (the surface's shifts,
/// turns and alignment, the colour searches of a faded or failed frame) are off. In doubt by the surface, the
/// keyframe's features are matched over the whole frame and find the box on the first frame
/// back (never lost); matched only around the held pose, they cannot (the old place is held,
/// 17 cm off, until the loss).
TEST(TrackingSession, ASurfaceInDoubtIsLookedForOverTheWholeFrame) {
  const Scene scene;
  const Pose start = test::make_pose(0.45);
  const Pose truth = test::move(start, 0.0, {0.0, 0.0, 1.0}, {0.15, -0.1, 0.0});
  for (const bool whole_frame : {false, true}) {
    SCOPED_TRACE(whole_frame ? "whole frame" : "around the held pose");
    TrackerParams params = quick_realtime();
    ASSERT_GT(params.relocalization_below_correlation, 0.0);
    params.tracked_search_ratio = 0.0;
    params.extrapolated_search_ratio = 0.0;
    without_pose_corrections(params);
    params.relocalization_doubt_whole_frame = whole_frame;
    TrackingSession session(scene.mesh, params);
    const CheckRun run = hide_and_show(session, scene.renderer, scene.camera, scene.background, start,
                                       truth, &SessionResult::relocalized);
    const Pose& first = run.first.frame.object_to_camera;
    if (whole_frame) {
      EXPECT_TRUE(run.first.relocalized) << "not relocalized on the first frame back";
      // 5 mm and 2 deg for a 12 cm box at 0.45 m, as the relocalization tests'.
      EXPECT_LT(translation_error(first, truth), 0.005);
      EXPECT_LT(rotation_error_deg(first, truth), 2.0);
      EXPECT_FALSE(run.lost);
    } else {
      EXPECT_FALSE(run.first.relocalized) << "found around the held pose: the test shows nothing";
      EXPECT_GT(translation_error(first, truth), 0.1);
      EXPECT_TRUE(run.lost) << "held at the old place until declared lost";
    }
  }
}

/// texture_align_below: a textured cube vanishes for a frame (KLT fails) and comes back at the
/// same place turned 15 deg about an axis that is none of its own (camera x and y mixed). The
/// check's turns about the cube's axes and rotation_check's turns about the camera's (off here)
/// do not apply; without the alignment the track holds the unturned pose (reported good); with
/// it the surface colours find the turn and it replaces the pose.
TEST(TrackingSession, TextureAlignmentFindsATurnAboutAnyAxis) {
  const CubeScene scene;
  const Pose& start = scene.start;
  const Pose truth =
      test::move(start, 15.0, Eigen::Vector3d(1.0, 1.0, 0.0), Eigen::Vector3d::Zero());
  ASSERT_GT(make_preset("realtime").texture_align_below, 0.0) << "realtime aligns the texture";
  for (const bool align : {false, true}) {
    TrackerParams params = quick_realtime();
    params.rotation_check_deg = 0.0;
    params.relocalization_below_correlation = 0.0;  // the features find the turn too
    params.texture_align_below = align ? 0.3 : 0.0;
    TrackingSession session(scene.cube, params);
    const CheckRun run = hide_and_show(session, scene.renderer, scene.camera, scene.background,
                                       start, truth, &SessionResult::texture_corrected);
    const SessionResult& r = run.last;
    const std::string what = align ? "with the alignment" : "without the alignment";
    ASSERT_EQ(r.state, TrackState::kTracking) << what;
    EXPECT_TRUE(r.good) << what;
    // Tolerances for a 10 cm cube at 0.45 m: 2 deg and 3 mm when found (measured 0.1 deg,
    // 0.7 mm); the wrong hold is the turn itself (measured 14.9 deg).
    if (align) {
      EXPECT_LT(rotation_error_deg(r.frame.object_to_camera, truth), 2.0) << what;
      EXPECT_LT(translation_error(r.frame.object_to_camera, truth), 0.003) << what;
      EXPECT_GE(run.corrections, 1) << what;
    } else {
      EXPECT_GT(rotation_error_deg(r.frame.object_to_camera, truth), 10.0)
          << "the turned cube was found without the alignment: the test shows nothing";
      EXPECT_EQ(run.corrections, 0) << what;
    }
  }
}

/// tracked_search_surface_drop: the textured cube stays where it is while a patch of its own
/// texture appears behind it, so that the ring around its outline shows its own colours and its
/// colour contrast fades; beside it a decoy appears, a cube of the same colours in another
/// pattern (its texture turned), standing out against the background. The tracked search's find,
/// the decoy, beats the held pose's faded colours; without the surface check it replaces the held
/// pose, with it the held pose, whose surface still matches the learned one, stays.
TEST(TrackingSession, ATrackedSearchFindWithoutTheObjectsSurfaceIsNotTaken) {
  const CubeScene scene;
  // The cube right of the middle, the decoy left of it, both whole in the image.
  const Pose start = test::move(test::make_pose(0.55), 0.0, Eigen::Vector3d::UnitZ(), {0.08, 0.0, 0.0});
  // The patch: the texture atlas, 260 px square, centred on the cube.
  cv::Mat patched_background = scene.background.clone();
  const Eigen::Vector2d centre_px = scene.camera.project(start * scene.cube->bounding_box_center());
  cv::Mat patch;
  cv::resize(scene.cube->texture, patch, cv::Size(260, 260));
  const cv::Rect patch_rect(cv::Point(static_cast<int>(centre_px.x()) - 130,
                                      static_cast<int>(centre_px.y()) - 130),
                            patch.size());
  patch.copyTo(patched_background(patch_rect));
  const Pose decoy_pose = test::move(start, 0.0, Eigen::Vector3d::UnitZ(), {-0.25, 0.0, 0.0});
  // The decoy stands on the background's mean colour: it stands out at least as well as the
  // cube did.
  const Eigen::Vector2d decoy_px = scene.camera.project(decoy_pose * scene.cube->bounding_box_center());
  cv::rectangle(patched_background, cv::Point2d(decoy_px.x() - 125, decoy_px.y() - 125),
                cv::Point2d(decoy_px.x() + 125, decoy_px.y() + 125), cv::mean(scene.background), cv::FILLED);
  auto decoy_mesh = std::make_shared<Mesh>(test::make_box(0.1, 0.1, 0.1));
  cv::flip(decoy_mesh->texture, decoy_mesh->texture, -1);  // the same colours, another pattern
  const Renderer decoy(decoy_mesh);
  ASSERT_GT(make_preset("realtime").tracked_search_surface_drop, 0.0) << "realtime checks the find";
  for (const bool check : {false, true}) {
    TrackerParams params = quick_realtime();
    params.tracked_search_surface_drop = check ? make_preset("realtime").tracked_search_surface_drop : 0.0;
    params.color_search_reach_diameters = 0.0;  // the decoy anywhere, as in the tests above
    TrackingSession session(scene.cube, params);
    session.set_camera(scene.camera);
    session.initialize(start);
    double stamp = 0.0;
    // A slightly soft camera: the contour energy's level is that of a soft outline.
    for (int i = 0; i < 8; ++i, stamp += 0.033) {
      cv::Mat frame = test::render_frame(scene.renderer, scene.camera, start, scene.background, 1.5, i);
      cv::GaussianBlur(frame, frame, cv::Size(0, 0), 1.0);
      const SessionResult r = session.track({frame, stamp});
      ASSERT_EQ(r.state, TrackState::kTracking) << i;
    }
    const std::string what = check ? "with the surface check" : "without it";
    int searched = 0;
    double worst_error_m = 0.0;
    for (int i = 0; i < 4; ++i, stamp += 0.033) {
      cv::Mat frame = test::render_frame(decoy, scene.camera, decoy_pose, patched_background, 0.0, 0);
      frame = test::render_frame(scene.renderer, scene.camera, start, frame, 1.5, 20 + i);
      // The cube and its patch blurred (it shakes): a weaker outline than the decoy's.
      cv::GaussianBlur(frame(patch_rect), frame(patch_rect), cv::Size(0, 0), 2.0);
      const SessionResult r = session.track({frame, stamp});
      searched += r.searched ? 1 : 0;
      worst_error_m = std::max(worst_error_m, translation_error(r.frame.object_to_camera, start));
    }
    if (check) {
      // Tolerance: 1 cm, as the re-acquisition tests (the held pose stays on the cube).
      EXPECT_LT(worst_error_m, 0.01) << what;
    } else {
      EXPECT_GT(searched, 0) << "the decoy was never searched for: the test shows nothing";
      EXPECT_GT(worst_error_m, 0.1) << "the decoy was not taken: the test shows nothing";
    }
  }
}

/// plain_surface_keypoint_scale: the surface learned on a uniformly coloured box's initial frame
/// has no colour pattern, so that track's refinement weighs its keypoints less; a printed box's
/// keeps the weight, and so does a track started on a grey frame (nothing learned). A new start
/// is judged again. contour_chroma_plain_only: the contour energy reads the chromaticity for
/// the plain box's track only.
TEST(TrackingSession, AnObjectWithoutAColourPatternWeighsItsKeypointsLess) {
  const TrackerParams params = quick_realtime();
  ASSERT_LT(params.plain_surface_keypoint_scale, 1.0) << "realtime scales them";
  ASSERT_TRUE(params.contour_chroma_plain_only && params.contour_chroma_weight > 0.0)
      << "realtime reads the chromaticity for plain objects";
  const double chroma = params.contour_chroma_weight;
  const double weight = params.keypoint_weight;
  const double plain_weight = weight * params.plain_surface_keypoint_scale;
  ASSERT_LT(plain_weight, weight);
  const PinholeCamera camera = test::make_camera();
  const cv::Mat background = test::make_background(camera.size(), 5) * 0.5 + cv::Scalar(90, 70, 40);
  const Pose start = test::make_pose(0.45);
  auto plain = std::make_shared<Mesh>(test::make_box(0.1, 0.1, 0.1, false));
  plain->base_color = cv::Vec3b(30, 120, 210);  // orange, as the benchmark's toy
  auto printed = std::make_shared<Mesh>(test::make_box(0.1, 0.1, 0.1, true));
  const auto frame_of = [&](const Renderer& renderer, bool grey) {
    cv::Mat frame = test::render_frame(renderer, camera, start, background, 1.5, 0);
    if (grey) cv::cvtColor(frame, frame, cv::COLOR_BGR2GRAY);
    return frame;
  };
  struct Case {
    std::shared_ptr<Mesh> mesh;
    bool grey, plain;
    const char* what;
  };
  for (const Case& c : {Case{plain, false, true, "plain box"}, Case{printed, false, false, "printed box"},
                        Case{plain, true, false, "plain box, grey frame"}}) {
    const Renderer renderer(c.mesh);
    TrackingSession session(c.mesh, params);
    session.set_camera(camera);
    session.initialize(start);
    EXPECT_FALSE(session.plain_surface()) << c.what << ": nothing learned before the first frame";
    double stamp = 0.0;
    for (int i = 0; i < 3; ++i, stamp += 0.033)
      ASSERT_EQ(session.track({frame_of(renderer, c.grey), stamp}).state, TrackState::kTracking) << c.what;
    EXPECT_EQ(session.plain_surface(), c.plain) << c.what;
    EXPECT_DOUBLE_EQ(session.tracker().params().keypoint_weight, c.plain ? plain_weight : weight) << c.what;
    EXPECT_DOUBLE_EQ(session.params().keypoint_weight, weight) << c.what << ": the session's own params keep it";
    EXPECT_DOUBLE_EQ(session.tracker().params().contour_chroma_weight, c.plain ? chroma : 0.0)
        << c.what;
    EXPECT_DOUBLE_EQ(session.params().contour_chroma_weight, chroma) << c.what;
    // Started again on a grey frame: nothing learned, the weight is the preset's again.
    session.initialize(start);
    session.track({frame_of(renderer, true), stamp});
    EXPECT_FALSE(session.plain_surface()) << c.what;
    EXPECT_DOUBLE_EQ(session.tracker().params().keypoint_weight, weight) << c.what;
    EXPECT_DOUBLE_EQ(session.tracker().params().contour_chroma_weight, 0.0) << c.what;
  }
}

}  // namespace
}  // namespace kct
