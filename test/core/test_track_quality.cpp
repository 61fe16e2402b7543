// The quality score and the WAITING_FOR_POSE / TRACKING / LOST state machine, on hand-made
// TrackResults (the score only reads the result's statistics).
#include <gtest/gtest.h>

#include "klt_contour_tracker/core/track_quality.h"

namespace kct {
namespace {

TrackResult refined_result(double energy_after, bool klt_success, double inlier_ratio) {
  TrackResult r;
  r.status = klt_success ? TrackStatus::kKeypoints : TrackStatus::kExtrapolated;
  r.refined = true;
  r.energy_after = energy_after;
  r.keypoints.success = klt_success;
  r.keypoints.inlier_ratio = inlier_ratio;
  r.object_to_camera = Pose::Identity();
  r.object_to_camera.translation() = Eigen::Vector3d(0, 0, 0.5);
  return r;
}

/// Colour evidence whose surface correlates at `matching`, at `differing`, and is not scored.
struct SurfaceEvidence {
  ColorEvidence matching, differing, unscored;
};
SurfaceEvidence surface_evidence(double matching, double differing) {
  SurfaceEvidence e;
  e.matching.surface_correlation = matching;
  e.differing.surface_correlation = differing;
  return e;
}

TEST(TrackQuality, ScoreMixesEnergyRatioAndInlierRatio) {
  TrackQualityParams params;
  params.energy_weight = 0.7;
  params.energy_level_smoothing = 1.0;  // level = the last good energy
  TrackQualityMonitor monitor(params);
  monitor.on_initialized(Pose::Identity());
  // No level yet: the energy cue counts as 1.
  EXPECT_NEAR(monitor.score(refined_result(10.0, true, 0.5)), 0.7 + 0.3 * 0.5, 1e-12);
  monitor.update(refined_result(20.0, true, 1.0));
  EXPECT_DOUBLE_EQ(monitor.energy_level(), 20.0);
  // Half the level, KLT failed: 0.7 * 0.5.
  EXPECT_NEAR(monitor.score(refined_result(10.0, false, 0.9)), 0.35, 1e-12);
  // Above the level the energy cue saturates at 1.
  EXPECT_NEAR(monitor.score(refined_result(40.0, true, 0.8)), 0.7 + 0.3 * 0.8, 1e-12);
  // Without refinement (klt_only) the score is the inlier ratio.
  TrackResult klt = refined_result(0.0, true, 0.42);
  klt.refined = false;
  EXPECT_NEAR(monitor.score(klt), 0.42, 1e-12);
  klt.keypoints.success = false;
  EXPECT_EQ(monitor.score(klt), 0.0);
  TrackResult initialized;
  initialized.status = TrackStatus::kInitialized;
  EXPECT_EQ(monitor.score(initialized), 1.0);
}

TEST(TrackQuality, EnergyLevelIsAMovingAverageOfGoodFramesOnly) {
  TrackQualityParams params;
  params.energy_level_smoothing = 0.5;
  TrackQualityMonitor monitor(params);
  monitor.on_initialized(Pose::Identity());
  monitor.update(refined_result(10.0, true, 1.0));
  monitor.update(refined_result(20.0, true, 1.0));
  EXPECT_DOUBLE_EQ(monitor.energy_level(), 15.0);
  monitor.update(refined_result(1.0, false, 0.0));  // bad: 0.7 * 1/15 < 0.5
  EXPECT_FALSE(monitor.last_good());
  EXPECT_DOUBLE_EQ(monitor.energy_level(), 15.0);
}

TEST(TrackQuality, ColourEvidenceMakesAFrameBadWhenTheOutlineStopsSeparatingTheColours) {
  TrackQualityParams params;
  params.energy_level_smoothing = 1.0;  // levels = the last good frame's
  TrackQualityMonitor monitor(params);
  monitor.on_initialized(Pose::Identity());
  ColorEvidence color;
  color.valid = true;
  color.contrast = 0.8;
  color.visible_fraction = 1.0;
  monitor.update(refined_result(10.0, true, 1.0), color, ColorLossRule{0.4});
  EXPECT_TRUE(monitor.last_good());
  EXPECT_DOUBLE_EQ(monitor.color_level(), 0.8);
  // Energy and keypoints fine, contrast 0.3 < 0.4 x 0.8: bad, and the level stays.
  color.contrast = 0.3;
  monitor.update(refined_result(10.0, true, 1.0), color, ColorLossRule{0.4});
  EXPECT_FALSE(monitor.last_good());
  EXPECT_DOUBLE_EQ(monitor.color_level(), 0.8);
  // 0.33 > 0.32: good again.
  color.contrast = 0.33;
  monitor.update(refined_result(10.0, true, 1.0), color, ColorLossRule{0.4});
  EXPECT_TRUE(monitor.last_good());
  // Less than 10 % of the object in the image: bad whatever the other cues say.
  color.contrast = 0.8;
  color.visible_fraction = 0.05;
  monitor.update(refined_result(10.0, true, 1.0), color, ColorLossRule{0.4});
  EXPECT_FALSE(monitor.last_good());
  // Without colour evidence (grey frames) nothing changes.
  monitor.update(refined_result(10.0, true, 1.0), ColorEvidence{}, ColorLossRule{0.4});
  EXPECT_TRUE(monitor.last_good());
}

/// A monitor after one good refined frame with energy 10 and colour contrast 0.8 (its levels, with
/// energy_level_smoothing 1).
TrackQualityMonitor monitor_at_levels(const TrackQualityParams& params, const ColorLossRule& rule) {
  TrackQualityMonitor monitor(params);
  monitor.on_initialized(Pose::Identity());
  ColorEvidence color;
  color.valid = true;
  color.contrast = 0.8;
  color.visible_fraction = 1.0;
  monitor.update(refined_result(10.0, true, 1.0), color, rule);
  EXPECT_TRUE(monitor.last_good());
  return monitor;
}

TEST(TrackQuality, TheContourOrKltVetoAFadedColourVerdictUnlessTheColoursVanished) {
  TrackQualityParams params;
  params.energy_level_smoothing = 1.0;  // levels = the last good frame's
  ColorLossRule rule;
  rule.lost_ratio = 0.6;
  rule.contour_veto_ratio = 0.85;
  rule.vanished_ratio = 0.15;
  ColorEvidence color;
  color.valid = true;
  color.visible_fraction = 1.0;
  for (const double veto : {0.0, 0.85}) {
    rule.contour_veto_ratio = veto;
    TrackQualityMonitor monitor = monitor_at_levels(params, rule);  // energy 10, colour 0.8
    // Contrast 0.3 < 0.6 x 0.8 (faded), energy 9 >= 0.85 x 10: the contour holds when the veto is on.
    color.contrast = 0.3;
    monitor.update(refined_result(9.0, true, 1.0), color, rule);
    EXPECT_EQ(monitor.last_good(), veto > 0.0) << "veto " << veto;
    // A vetoed frame is a good frame: both levels follow it (the colours changed, not the pose).
    EXPECT_DOUBLE_EQ(monitor.energy_level(), veto > 0.0 ? 9.0 : 10.0);
    EXPECT_DOUBLE_EQ(monitor.color_level(), veto > 0.0 ? 0.3 : 0.8);
    // Contrast 0.1 (faded either way), energy 7 < 0.85 x 9 (or x 10): the colour verdict stands.
    color.contrast = 0.1;
    monitor.update(refined_result(7.0, true, 1.0), color, rule);
    EXPECT_FALSE(monitor.last_good()) << "veto " << veto;
  }
  // Energy at the level but the contrast 0.1 < 0.15 x 0.8: the colours vanished, bad.
  TrackQualityMonitor monitor = monitor_at_levels(params, rule);
  color.contrast = 0.1;
  monitor.update(refined_result(10.0, true, 1.0), color, rule);
  EXPECT_FALSE(monitor.last_good());
  // Without refinement there is no contour to veto with.
  TrackResult klt = refined_result(10.0, true, 1.0);
  klt.refined = false;
  klt.keypoints.inliers = 150;
  color.contrast = 0.3;
  monitor.update(klt, color, rule);
  EXPECT_FALSE(monitor.last_good());
  // ... but 150 KLT inliers at a ratio of 0.97 veto it when keypoint_veto_inliers <= 150, not
  // at a ratio of 0.9, and not once the colours vanished.
  rule.keypoint_veto_inliers = 100;
  klt.keypoints.inlier_ratio = 0.97;
  monitor.update(klt, color, rule);
  EXPECT_TRUE(monitor.last_good());
  TrackQualityMonitor fresh = monitor_at_levels(params, rule);
  color.contrast = 0.3;
  klt.keypoints.inlier_ratio = 0.9;
  fresh.update(klt, color, rule);
  EXPECT_FALSE(fresh.last_good());
  klt.keypoints.inlier_ratio = 0.97;
  color.contrast = 0.1;
  fresh.update(klt, color, rule);
  EXPECT_FALSE(fresh.last_good());
  color.contrast = 0.3;
  klt.keypoints.inliers = 99;
  fresh.update(klt, color, rule);
  EXPECT_FALSE(fresh.last_good());
  // The ratio is the rule's: at keypoint_veto_inlier_ratio 0.9 (realtime's), 150 inliers at a
  // ratio of 0.92 (an occluder's edge costs a few) veto it, at 0.89 they do not.
  rule.keypoint_veto_inlier_ratio = 0.9;
  TrackQualityMonitor occluded = monitor_at_levels(params, rule);
  klt.keypoints.inliers = 150;
  klt.keypoints.inlier_ratio = 0.92;
  occluded.update(klt, color, rule);
  EXPECT_TRUE(occluded.last_good());
  TrackQualityMonitor fewer = monitor_at_levels(params, rule);  // (the vetoed frame set the level)
  klt.keypoints.inlier_ratio = 0.89;
  fewer.update(klt, color, rule);
  EXPECT_FALSE(fewer.last_good());
}

TEST(TrackQuality, AWeakColourModelIsNotEvidence) {
  TrackQualityParams params;
  params.energy_level_smoothing = 1.0;
  TrackQualityMonitor monitor(params);
  monitor.on_initialized(Pose::Identity());
  ColorEvidence color;
  color.valid = true;
  color.contrast = 0.15;  // below kMinColorLevel at a good pose: the colours barely differ
  monitor.update(refined_result(10.0, true, 1.0), color, ColorLossRule{0.6});
  ASSERT_TRUE(monitor.last_good());
  ASSERT_LT(monitor.color_level(), TrackQualityMonitor::kMinColorLevel);
  color.contrast = 0.0;  // would be "faded" with a useful model
  monitor.update(refined_result(10.0, true, 1.0), color, ColorLossRule{0.6});
  EXPECT_TRUE(monitor.last_good());
}

TEST(TrackQuality, WhileLostARecoveryNeedsTheColoursAndMostOfTheSilhouetteInTheImage) {
  TrackQualityParams params;
  params.energy_level_smoothing = 1.0;  // levels = the last good frame's
  params.lost_after_bad_frames = 1;
  params.recover_after_good_frames = 1;
  ColorLossRule rule;
  rule.lost_ratio = 0.6;
  rule.contour_veto_ratio = 0.85;
  rule.keypoint_veto_inliers = 100;
  rule.vanished_ratio = 0.15;
  rule.recover_ratio = 0.5;
  rule.recover_min_visible = 0.5;
  ColorEvidence color;
  color.valid = true;
  color.visible_fraction = 1.0;
  // A static distractor: energy at the level, 150 KLT inliers at a ratio of 1, contrast 0.3.
  TrackResult held = refined_result(10.0, true, 1.0);
  held.keypoints.inliers = 150;
  TrackQualityMonitor monitor = monitor_at_levels(params, rule);  // energy 10, colour 0.8
  // While tracking, 0.3 < 0.6 x 0.8 is faded but the vetoes hold: good (and the colour level
  // follows it to 0.3).
  color.contrast = 0.3;
  EXPECT_EQ(monitor.update(held, color, rule), TrackState::kTracking);
  EXPECT_TRUE(monitor.last_good());
  // Lost (out of view) ...
  ColorEvidence outside = color;
  outside.visible_fraction = 0.05;
  EXPECT_EQ(monitor.update(held, outside, rule), TrackState::kLost);
  // ... a frame whose contrast is below 0.5 x the level (0.1 < 0.15) does not recover, however
  // well the contour and the keypoints hold.
  color.contrast = 0.1;
  EXPECT_EQ(monitor.update(held, color, rule), TrackState::kLost);
  EXPECT_FALSE(monitor.last_good());
  // The colours right but only 40% of the silhouette in the image: not yet.
  color.contrast = 0.3;
  color.visible_fraction = 0.4;
  EXPECT_EQ(monitor.update(held, color, rule), TrackState::kLost);
  // Both: recovered.
  color.visible_fraction = 0.6;
  EXPECT_EQ(monitor.update(held, color, rule), TrackState::kTracking);
  // With the rule off (0), the contour's veto recovers a frame the rule refuses on both counts
  // (contrast 0.3 < 0.5 x 0.8, 40% in the image), as before.
  rule.recover_ratio = rule.recover_min_visible = 0.0;
  TrackQualityMonitor off = monitor_at_levels(params, rule);  // colour level 0.8
  EXPECT_EQ(off.update(held, outside, rule), TrackState::kLost);
  color.contrast = 0.3;  // faded (< 0.6 x 0.8) but vetoed: 0.3 >= 0.15 x 0.8
  color.visible_fraction = 0.4;
  EXPECT_EQ(off.update(held, color, rule), TrackState::kTracking);
}

TEST(TrackQuality, LostAfterTheStatedBadFramesAndRecoversAfterTheStatedGoodFrames) {
  TrackQualityParams params;
  params.lost_after_bad_frames = 3;
  params.recover_after_good_frames = 2;
  TrackQualityMonitor monitor(params);
  EXPECT_EQ(monitor.state(), TrackState::kWaitingForPose);
  Pose given = Pose::Identity();
  given.translation() = Eigen::Vector3d(0.1, 0, 0.4);
  monitor.on_initialized(given);
  EXPECT_EQ(monitor.state(), TrackState::kTracking);

  TrackResult good = refined_result(10.0, true, 0.9);
  good.object_to_camera.translation() = Eigen::Vector3d(0.2, 0, 0.4);
  const TrackResult bad = refined_result(1.0, false, 0.0);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(monitor.update(good), TrackState::kTracking);
  // Two bad frames and a good one: the bad count restarts.
  EXPECT_EQ(monitor.update(bad), TrackState::kTracking);
  EXPECT_EQ(monitor.update(bad), TrackState::kTracking);
  EXPECT_EQ(monitor.update(good), TrackState::kTracking);
  EXPECT_EQ(monitor.update(bad), TrackState::kTracking);
  EXPECT_EQ(monitor.update(bad), TrackState::kTracking);
  EXPECT_FALSE(monitor.should_reacquire());
  EXPECT_EQ(monitor.update(bad), TrackState::kLost);
  EXPECT_TRUE(monitor.should_reacquire());
  EXPECT_EQ(monitor.consecutive_bad_frames(), 3);
  // The last good pose is the last good frame's, not the bad frames'.
  EXPECT_LT(translation_error(monitor.last_good_pose(), good.object_to_camera), 1e-12);

  // One good frame while lost is not enough; a bad one in between restarts the count.
  EXPECT_EQ(monitor.update(good), TrackState::kLost);
  EXPECT_FALSE(monitor.should_reacquire());
  EXPECT_EQ(monitor.update(bad), TrackState::kLost);
  EXPECT_TRUE(monitor.should_reacquire());
  EXPECT_EQ(monitor.update(good), TrackState::kLost);
  EXPECT_EQ(monitor.update(good), TrackState::kTracking);
  EXPECT_EQ(monitor.consecutive_bad_frames(), 0);
}

/// surface_hold_correlation: bad tracked frames whose surface colours still match are held
/// (neither counted towards the loss nor learned from); below the bar, while lost, or with no
/// surface score they count as before.
TEST(TrackQuality, ASurfaceThatStillMatchesHoldsABadTrackedFrame) {
  TrackQualityParams params;
  params.lost_after_bad_frames = 3;
  params.energy_level_smoothing = 1.0;  // level = the last good energy
  ColorLossRule rule;
  rule.surface_hold_correlation = 0.7;
  const SurfaceEvidence surface = surface_evidence(0.75, 0.69);
  const ColorEvidence &matching = surface.matching, &differing = surface.differing,
                      &unscored = surface.unscored;
  const TrackResult good = refined_result(10.0, true, 0.9);
  const TrackResult blurred = refined_result(2.0, true, 0.2);       // bad: 0.7 * 0.2 + 0.3 * 0.2
  const TrackResult extrapolated = refined_result(2.0, false, 0.0);  // bad, KLT failed

  TrackQualityMonitor monitor(params);
  monitor.on_initialized(Pose::Identity());
  monitor.update(good, {}, rule);
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(monitor.update(i % 2 ? blurred : extrapolated, matching, rule), TrackState::kTracking);
    EXPECT_FALSE(monitor.last_good());
    EXPECT_TRUE(monitor.last_held());
  }
  EXPECT_EQ(monitor.consecutive_bad_frames(), 0);
  EXPECT_DOUBLE_EQ(monitor.energy_level(), 10.0);  // nothing learned from held frames
  // Just below the bar, or without a surface score: bad frames, lost after 3.
  EXPECT_EQ(monitor.update(blurred, differing, rule), TrackState::kTracking);
  EXPECT_FALSE(monitor.last_held());
  EXPECT_EQ(monitor.update(blurred, unscored, rule), TrackState::kTracking);
  EXPECT_EQ(monitor.update(blurred, differing, rule), TrackState::kLost);
  // While lost a matching surface does not hold a frame (nor recover the track by itself).
  EXPECT_EQ(monitor.update(blurred, matching, rule), TrackState::kLost);
  EXPECT_FALSE(monitor.last_held());
  EXPECT_EQ(monitor.consecutive_bad_frames(), 4);

  // Off (0): the same frames are lost after 3.
  TrackQualityMonitor off(params);
  off.on_initialized(Pose::Identity());
  off.update(good);
  ColorLossRule none;
  EXPECT_EQ(off.update(blurred, matching, none), TrackState::kTracking);
  EXPECT_EQ(off.update(blurred, matching, none), TrackState::kTracking);
  EXPECT_EQ(off.update(blurred, matching, none), TrackState::kLost);
}

/// recover_min_surface_correlation: while lost, a tracked frame whose surface colours do not
/// match (a static patch of the background the keypoints hold) does not count towards the
/// recovery, however good its energy and keypoints; an unscored surface, a re-acquisition's find
/// and a frame while tracking are not held back.
TEST(TrackQuality, ASurfaceThatDoesNotMatchKeepsTheTrackLost) {
  TrackQualityParams params;
  params.lost_after_bad_frames = 2;
  params.recover_after_good_frames = 2;
  params.energy_level_smoothing = 1.0;  // level = the last good energy
  ColorLossRule rule;
  rule.recover_min_surface_correlation = 0.3;
  const SurfaceEvidence surface = surface_evidence(0.8, 0.29);
  const ColorEvidence &matching = surface.matching, &differing = surface.differing,
                      &unscored = surface.unscored;
  const TrackResult good = refined_result(10.0, true, 1.0);
  const TrackResult bad = refined_result(1.0, false, 0.0);
  TrackResult found = good;
  found.status = TrackStatus::kReacquired;

  const auto lost_monitor = [&]() {
    TrackQualityMonitor m(params);
    m.on_initialized(Pose::Identity());
    m.update(good, matching, rule);
    m.update(bad, matching, rule);
    EXPECT_EQ(m.update(bad, matching, rule), TrackState::kLost);
    return m;
  };
  // While tracking, a differing surface does not make a good frame bad.
  TrackQualityMonitor tracking(params);
  tracking.on_initialized(Pose::Identity());
  EXPECT_EQ(tracking.update(good, differing, rule), TrackState::kTracking);
  EXPECT_TRUE(tracking.last_good());

  // Lost: good tracked frames on a differing surface stay bad and keep the re-acquisition on.
  TrackQualityMonitor held_back = lost_monitor();
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(held_back.update(good, differing, rule), TrackState::kLost);
    EXPECT_FALSE(held_back.last_good());
    EXPECT_TRUE(held_back.should_reacquire());
  }
  // The same frames on the matching surface, or unscored, recover it after 2.
  EXPECT_EQ(held_back.update(good, matching, rule), TrackState::kLost);
  EXPECT_EQ(held_back.update(good, unscored, rule), TrackState::kTracking);
  // A re-acquisition's find is not held back by the surface.
  TrackQualityMonitor finds = lost_monitor();
  EXPECT_EQ(finds.update(found, differing, rule), TrackState::kLost);
  EXPECT_TRUE(finds.last_good());
  EXPECT_EQ(finds.update(found, differing, rule), TrackState::kTracking);

  // Off (0): the differing surface recovers after 2.
  ColorLossRule off;
  TrackQualityMonitor unchecked = lost_monitor();
  EXPECT_EQ(unchecked.update(good, differing, off), TrackState::kLost);
  EXPECT_EQ(unchecked.update(good, differing, off), TrackState::kTracking);
}

/// extrapolated_good_frames: the first N frames in a row that KLT failed on can be good, later
/// ones are bad until KLT tracks again; -1 (off) leaves them to their score.
TEST(TrackQuality, OnlyTheFirstExtrapolatedFramesInARowCanBeGood) {
  TrackQualityParams params;
  params.lost_after_bad_frames = 3;
  params.energy_level_smoothing = 1.0;
  const TrackResult tracked = refined_result(10.0, true, 1.0);
  const TrackResult extrapolated = refined_result(10.0, false, 0.0);  // 0.7: good by its score
  ColorLossRule rule;
  rule.extrapolated_good_frames = 2;

  TrackQualityMonitor monitor(params);
  monitor.on_initialized(Pose::Identity());
  monitor.update(tracked, {}, rule);
  for (int round = 0; round < 2; ++round) {  // KLT tracking again starts the count over
    for (int i = 0; i < 2; ++i) {
      EXPECT_EQ(monitor.update(extrapolated, {}, rule), TrackState::kTracking);
      EXPECT_TRUE(monitor.last_good());
      EXPECT_NEAR(monitor.last_quality(), 0.7, 1e-12);
    }
    EXPECT_EQ(monitor.update(extrapolated, {}, rule), TrackState::kTracking);
    EXPECT_FALSE(monitor.last_good());
    EXPECT_LT(monitor.last_quality(), params.min_quality);
    EXPECT_TRUE(monitor.update(tracked, {}, rule) == TrackState::kTracking && monitor.last_good());
  }
  // The third and later extrapolated frames in a row count towards the loss.
  for (int i = 0; i < 2; ++i) monitor.update(extrapolated, {}, rule);
  EXPECT_EQ(monitor.update(extrapolated, {}, rule), TrackState::kTracking);
  EXPECT_EQ(monitor.update(extrapolated, {}, rule), TrackState::kTracking);
  EXPECT_EQ(monitor.update(extrapolated, {}, rule), TrackState::kLost);

  // Off: every one of them is good.
  TrackQualityMonitor off(params);
  off.on_initialized(Pose::Identity());
  off.update(tracked);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(off.update(extrapolated), TrackState::kTracking);
  EXPECT_TRUE(off.last_good());
  // 0: none is.
  rule.extrapolated_good_frames = 0;
  TrackQualityMonitor none(params);
  none.on_initialized(Pose::Identity());
  none.update(tracked, {}, rule);
  none.update(extrapolated, {}, rule);
  EXPECT_FALSE(none.last_good());
}

/// outside_trusted_depth (the session's trusted_depth_ratio): such a frame is bad whatever its
/// score, and counts towards the loss.
TEST(TrackQuality, APoseOutsideTheTrustedDepthIsBad) {
  TrackQualityParams params;
  params.lost_after_bad_frames = 2;
  const TrackResult tracked = refined_result(10.0, true, 1.0);
  ColorLossRule outside;
  outside.outside_trusted_depth = true;
  TrackQualityMonitor monitor(params);
  monitor.on_initialized(Pose::Identity());
  monitor.update(tracked);
  EXPECT_TRUE(monitor.last_good());
  EXPECT_EQ(monitor.update(tracked, {}, outside), TrackState::kTracking);
  EXPECT_FALSE(monitor.last_good());
  EXPECT_LT(monitor.last_quality(), params.min_quality);
  EXPECT_EQ(monitor.update(tracked, {}, outside), TrackState::kLost);
  EXPECT_EQ(monitor.update(tracked, {}, ColorLossRule()), TrackState::kLost);
  EXPECT_TRUE(monitor.last_good()) << "inside the range again: judged by its score";
}

/// repeats_previous_find (the session's repeat_recover_diameters): while LOST a find at the
/// previous frame's find is good whatever its score, so the track recovers after
/// recover_after_good_frames of them; while TRACKING it changes nothing, and the colour recovery
/// rule still vetoes it.
TEST(TrackQuality, AFindRepeatedWhileLostCountsAsGood) {
  TrackQualityParams params;
  params.lost_after_bad_frames = 3;
  params.recover_after_good_frames = 3;
  params.energy_level_smoothing = 1.0;  // level = the last good energy
  TrackResult find = refined_result(4.0, false, 0.0);  // 0.7 * 0.4: bad by its score
  find.status = TrackStatus::kReacquired;
  const TrackResult good = refined_result(10.0, true, 0.9);

  TrackQualityMonitor monitor(params);
  monitor.on_initialized(Pose::Identity());
  monitor.update(good);
  // While tracking a repeated find is bad as scored: lost after 3.
  EXPECT_EQ(monitor.update(find, {}, {}, true), TrackState::kTracking);
  EXPECT_FALSE(monitor.last_good());
  EXPECT_EQ(monitor.update(find, {}, {}, true), TrackState::kTracking);
  EXPECT_EQ(monitor.update(find, {}, {}, true), TrackState::kLost);
  // Lost: not repeated, bad; repeated, good (its score unchanged); recovered after 3.
  EXPECT_EQ(monitor.update(find, {}, {}, false), TrackState::kLost);
  EXPECT_FALSE(monitor.last_good());
  EXPECT_EQ(monitor.update(find, {}, {}, true), TrackState::kLost);
  EXPECT_TRUE(monitor.last_good());
  EXPECT_NEAR(monitor.last_quality(), 0.28, 1e-9);
  EXPECT_EQ(monitor.update(find, {}, {}, true), TrackState::kLost);
  EXPECT_EQ(monitor.update(find, {}, {}, true), TrackState::kTracking);

  // The colour recovery rule still applies: a repeated find whose colours faded stays bad.
  TrackQualityMonitor vetoed(params);
  vetoed.on_initialized(Pose::Identity());
  ColorEvidence bright, faded;
  bright.valid = faded.valid = true;
  bright.contrast = 0.6;
  faded.contrast = 0.2;
  ColorLossRule rule;
  rule.recover_ratio = 0.5;
  vetoed.update(good, bright, rule);
  for (int i = 0; i < 3; ++i) vetoed.update(find, bright, rule);
  ASSERT_EQ(vetoed.state(), TrackState::kLost);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(vetoed.update(find, faded, rule, true), TrackState::kLost) << i;
    EXPECT_FALSE(vetoed.last_good()) << i;
  }
}

TEST(TrackQuality, InvalidInputChangesNothingAndNotInitializedMeansWaiting) {
  TrackQualityParams params;
  params.lost_after_bad_frames = 1;
  TrackQualityMonitor monitor(params);
  monitor.on_initialized(Pose::Identity());
  TrackResult invalid;
  invalid.status = TrackStatus::kInvalidInput;
  for (int i = 0; i < 5; ++i) EXPECT_EQ(monitor.update(invalid), TrackState::kTracking);
  TrackResult waiting;
  waiting.status = TrackStatus::kNotInitialized;
  EXPECT_EQ(monitor.update(waiting), TrackState::kWaitingForPose);
  monitor.on_initialized(Pose::Identity());
  monitor.reset();
  EXPECT_EQ(monitor.state(), TrackState::kWaitingForPose);
  EXPECT_STREQ(to_string(TrackState::kLost), "lost");
  EXPECT_STREQ(to_string(TrackState::kWaitingForPose), "waiting_for_pose");
}

TEST(TrackQuality, InitializationForgetsTheEnergyLevel) {
  TrackQualityMonitor monitor;
  monitor.on_initialized(Pose::Identity());
  monitor.update(refined_result(50.0, true, 1.0));
  EXPECT_GT(monitor.energy_level(), 0.0);
  monitor.on_initialized(Pose::Identity());
  EXPECT_EQ(monitor.energy_level(), 0.0);
  EXPECT_NEAR(monitor.score(refined_result(5.0, false, 0.0)), 0.7, 1e-12);
}

TEST(TrackQuality, QualityParametersAreSetByNameAsTheNodeletsAre) {
  TrackQualityParams params;
  set_quality_param(params, "lost_after_bad_frames", "8");
  set_quality_param(params, "recover_after_good_frames", "2");
  set_quality_param(params, "min_quality", "0.4");
  set_quality_param(params, "energy_weight", "0.6");
  set_quality_param(params, "energy_level_smoothing", "0.2");
  set_quality_param(params, "reacquire_search_scale", "3");
  EXPECT_EQ(params.lost_after_bad_frames, 8);
  EXPECT_EQ(params.recover_after_good_frames, 2);
  EXPECT_DOUBLE_EQ(params.min_quality, 0.4);
  EXPECT_DOUBLE_EQ(params.energy_weight, 0.6);
  EXPECT_DOUBLE_EQ(params.energy_level_smoothing, 0.2);
  EXPECT_DOUBLE_EQ(params.reacquire_search_scale, 3.0);
  EXPECT_NO_THROW(params.validate());
  // Unknown names, text that is not a number, a fraction for a frame count: refused, unchanged.
  EXPECT_THROW(set_quality_param(params, "lost_after", "8"), std::invalid_argument);
  EXPECT_THROW(set_quality_param(params, "min_quality", "high"), std::invalid_argument);
  EXPECT_THROW(set_quality_param(params, "min_quality", ""), std::invalid_argument);
  EXPECT_THROW(set_quality_param(params, "lost_after_bad_frames", "2.5"), std::invalid_argument);
  EXPECT_EQ(params.lost_after_bad_frames, 8);
  EXPECT_DOUBLE_EQ(params.min_quality, 0.4);
  // The range is validate()'s.
  set_quality_param(params, "min_quality", "1.5");
  EXPECT_THROW(params.validate(), std::invalid_argument);
}

TEST(TrackQuality, ParametersAreValidated) {
  TrackQualityParams params;
  EXPECT_NO_THROW(params.validate());
  auto expect_invalid = [](auto spoil, const char* field) {
    TrackQualityParams p;
    spoil(p);
    try {
      p.validate();
      ADD_FAILURE() << field << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  expect_invalid([](TrackQualityParams& p) { p.energy_weight = 1.5; }, "energy_weight");
  expect_invalid([](TrackQualityParams& p) { p.min_quality = -0.1; }, "min_quality");
  expect_invalid([](TrackQualityParams& p) { p.energy_level_smoothing = 0.0; }, "energy_level_smoothing");
  expect_invalid([](TrackQualityParams& p) { p.lost_after_bad_frames = 0; }, "lost_after_bad_frames");
  expect_invalid([](TrackQualityParams& p) { p.recover_after_good_frames = 0; }, "recover_after_good_frames");
  expect_invalid([](TrackQualityParams& p) { p.reacquire_search_scale = 0.5; }, "reacquire_search_scale");
  expect_invalid([](TrackQualityParams& p) { p.min_quality = std::nan(""); }, "min_quality");
  params.lost_after_bad_frames = 0;
  EXPECT_THROW(TrackQualityMonitor{params}, std::invalid_argument);
}

}  // namespace
}  // namespace kct
