// TrackerParams: paper defaults, presets, validation and text overrides.
#include <gtest/gtest.h>

#include "klt_contour_tracker/core/tracker_params.h"

namespace kct {
namespace {

TEST(TrackerParams, PaperPresetHoldsThePapersValues) {
  const TrackerParams p = make_preset("paper");
  EXPECT_TRUE(p.refine);
  EXPECT_EQ(p.klt_min_points, 8);
  EXPECT_DOUBLE_EQ(p.klt_min_inlier_ratio, 0.3);
  EXPECT_DOUBLE_EQ(p.sharp_edge_angle_deg, 45.0);
  EXPECT_EQ(p.icosphere_subdivisions, 4);
  EXPECT_DOUBLE_EQ(p.blur_sigma_px, 1.1);
  EXPECT_EQ(p.final_hops, 5);
  EXPECT_DOUBLE_EQ(p.max_reprojection_increase_px, 2.5);
  EXPECT_DOUBLE_EQ(p.extrapolated_rotation_bound_deg, 30.0);
  EXPECT_DOUBLE_EQ(p.extrapolated_axial_bound, 0.2);
  EXPECT_DOUBLE_EQ(p.extrapolated_lateral_bound, 0.1);
  EXPECT_DOUBLE_EQ(p.hops_budget, 25000.0);
  EXPECT_EQ(p.min_hops_cap, 100);
  EXPECT_EQ(p.max_hops_without_improvement_cap, 30);
  EXPECT_EQ(p.max_hops_cap, 200);
  EXPECT_NO_THROW(p.validate());
}

TEST(TrackerParams, KltOnlySkipsTheRefinement) {
  EXPECT_FALSE(make_preset("klt_only").refine);
  EXPECT_EQ(make_preset("klt_only").redetect_interval_frames, 0);
  EXPECT_EQ(make_preset("paper").redetect_interval_frames, 1);
}

TEST(TrackerParams, PaperPresetHasNoCuesBeyondThePaper) {
  const TrackerParams p = make_preset("paper");
  EXPECT_EQ(p.keypoint_mask_erosion_px, 3);
  EXPECT_FALSE(p.motion_model);
  EXPECT_DOUBLE_EQ(p.keypoint_motion_gate_sigmas, 0.0);
  EXPECT_DOUBLE_EQ(p.motion_prior_weight, 0.0);
  EXPECT_DOUBLE_EQ(p.region_weight, 0.0);
  EXPECT_DOUBLE_EQ(p.contour_chroma_weight, 0.0);
  EXPECT_DOUBLE_EQ(p.rotation_check_deg, 0.0);
  EXPECT_DOUBLE_EQ(p.texture_check_margin, 0.0);
  EXPECT_FALSE(p.texture_check_every_frame);
  EXPECT_DOUBLE_EQ(p.texture_shift_search_below, 0.0);
  EXPECT_DOUBLE_EQ(p.texture_align_below, 0.0);
  EXPECT_DOUBLE_EQ(p.surface_hold_correlation, 0.0);
  EXPECT_DOUBLE_EQ(p.surface_recover_correlation, 0.0);
  EXPECT_EQ(p.extrapolated_good_frames, -1);
  EXPECT_DOUBLE_EQ(p.trusted_depth_ratio, 0.0);
}

TEST(TrackerParams, CueFieldsAreValidated) {
  const auto rejects = [](const char* name, const char* value) {
    TrackerParams p;
    set_param(p, name, value);
    try {
      p.validate();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what()).find(name) != std::string::npos;
    }
    return false;
  };
  EXPECT_TRUE(rejects("keypoint_mask_erosion_px", "-1"));
  EXPECT_TRUE(rejects("motion_velocity_smoothing", "0"));
  EXPECT_TRUE(rejects("motion_error_smoothing", "1.5"));
  EXPECT_TRUE(rejects("keypoint_motion_gate_sigmas", "-2"));
  EXPECT_TRUE(rejects("extrapolated_good_frames", "-2"));
  EXPECT_TRUE(rejects("trusted_depth_ratio", "1"));
  EXPECT_TRUE(rejects("trusted_depth_ratio", "-2"));
  EXPECT_TRUE(rejects("motion_prior_weight", "-0.1"));
  EXPECT_TRUE(rejects("region_weight", "-1"));
  EXPECT_TRUE(rejects("contour_chroma_weight", "-1"));
  EXPECT_TRUE(rejects("rotation_check_deg", "-5"));
  EXPECT_TRUE(rejects("rotation_check_frames", "0"));
  EXPECT_TRUE(rejects("rotation_check_margin", "-0.1"));
  EXPECT_TRUE(rejects("texture_check_margin", "-0.1"));
  EXPECT_TRUE(rejects("texture_check_step_deg", "0"));
  EXPECT_TRUE(rejects("region_line_half_length_px", "1"));
  EXPECT_TRUE(rejects("region_line_spacing_px", "0"));
  EXPECT_TRUE(rejects("region_band_px", "0"));
  EXPECT_TRUE(rejects("region_learning_rate", "2"));
  TrackerParams p;
  set_param(p, "motion_model", "true");
  set_param(p, "region_weight", "0.5");
  EXPECT_NO_THROW(p.validate());
  EXPECT_TRUE(p.motion_model);
}

TEST(TrackerParams, UnknownPresetNamesTheKnownOnes) {
  try {
    make_preset("fastest");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("paper"), std::string::npos);
  }
}

TEST(TrackerParams, ValidateNamesTheBadField) {
  TrackerParams p;
  p.blur_sigma_px = -1.0;
  try {
    p.validate();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("blur_sigma_px"), std::string::npos);
  }
  TrackerParams q;
  q.klt_window_px = 20;
  EXPECT_THROW(q.validate(), std::invalid_argument);
}

TEST(TrackerParams, SetParamParsesEachType) {
  TrackerParams p;
  set_param(p, "final_hops", "7");
  set_param(p, "blur_sigma_px", "0.5");
  set_param(p, "refine", "false");
  set_param(p, "visibility_cache_dir", "/tmp/x");
  set_param(p, "random_seed", "99");
  EXPECT_EQ(p.final_hops, 7);
  EXPECT_DOUBLE_EQ(p.blur_sigma_px, 0.5);
  EXPECT_FALSE(p.refine);
  EXPECT_EQ(p.visibility_cache_dir, "/tmp/x");
  EXPECT_EQ(p.random_seed, 99u);
  EXPECT_THROW(set_param(p, "final_hops", "seven"), std::invalid_argument);
  EXPECT_THROW(set_param(p, "no_such_field", "1"), std::invalid_argument);
}

TEST(TrackerParams, DescribeListsEveryFieldOnce) {
  const auto fields = describe(TrackerParams{});
  EXPECT_EQ(fields.size(), 115u);
  EXPECT_EQ(fields.front().first, "max_keypoints");
}

TEST(TrackerParams, RealtimePresetIsValidAndPaperIsTheDefaults) {
  const TrackerParams realtime = make_preset("realtime");
  EXPECT_NO_THROW(realtime.validate());
  EXPECT_EQ(realtime.optimizer, "coarse_to_fine");
  EXPECT_GE(realtime.num_threads, 2);
  EXPECT_EQ(preset_names().front(), "realtime");
  // `paper` stays the struct's defaults, with the paper's optimizer.
  EXPECT_EQ(describe(make_preset("paper")), describe(TrackerParams{}));
  EXPECT_EQ(make_preset("paper").optimizer, "basin_hopping");
  TrackerParams bad = realtime;
  bad.optimizer = "gradient_descent";
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = realtime;
  bad.num_threads = 0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = realtime;
  bad.keypoint_max_motion_deg = 200.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = realtime;
  bad.keypoint_prior_diameters = -0.1;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = realtime;
  bad.keypoint_prior_deg = 0.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = realtime;
  bad.color_lost_ratio = 1.5;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = realtime;
  bad.color_learn_interval_frames = 0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = realtime;
  bad.color_search_refined = -1;  // 0 = all
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  EXPECT_EQ(realtime.color_search_refined, 8);
  EXPECT_EQ(TrackerParams{}.color_search_refined, 0);
  bad = realtime;
  bad.color_search_mesh_error_diameters = 0.06;  // [0, 0.05]
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad.color_search_mesh_error_diameters = -0.001;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  EXPECT_DOUBLE_EQ(realtime.color_search_mesh_error_diameters, 0.001);
  EXPECT_EQ(TrackerParams{}.color_search_mesh_error_diameters, 0.0);  // the mesh as given
  bad = realtime;
  bad.hypothesis_mesh_error_diameters = 0.06;  // [0, 0.05]
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  EXPECT_DOUBLE_EQ(realtime.hypothesis_mesh_error_diameters, 0.001);
  EXPECT_EQ(TrackerParams{}.hypothesis_mesh_error_diameters, 0.0);
  bad = realtime;
  bad.relocalization_interval_frames = 0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  EXPECT_EQ(realtime.relocalization_interval_frames, 2);
  EXPECT_EQ(TrackerParams{}.relocalization_interval_frames, 1);
  bad = realtime;
  bad.relocalization_override_inliers = 3;  // fewer than PnP + a check need
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  // The feature relocalizer is realtime's, and only while lost (it costs nothing while
  // tracking); paper stays the paper's method.
  EXPECT_TRUE(realtime.feature_relocalization);
  EXPECT_FALSE(realtime.relocalization_while_tracking);
  EXPECT_FALSE(make_preset("paper").feature_relocalization);
  EXPECT_FALSE(make_preset("klt_only").feature_relocalization);
  // ... and on a tracked frame whose surface does not correlate (a doubt), paper never.
  EXPECT_GT(realtime.relocalization_below_correlation, 0.0);
  EXPECT_EQ(make_preset("paper").relocalization_below_correlation, 0.0);
  // ... there over the whole frame when not found around the held pose.
  EXPECT_TRUE(realtime.relocalization_doubt_whole_frame);
  EXPECT_FALSE(make_preset("paper").relocalization_doubt_whole_frame);
  bad = realtime;
  bad.relocalization_below_correlation = 1.5;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  // The session's colour model and the PnP motion bounds are ours: off in paper and klt_only.
  EXPECT_TRUE(realtime.color_search);
  EXPECT_FALSE(make_preset("paper").color_search);
  EXPECT_FALSE(make_preset("klt_only").color_search);
  EXPECT_EQ(make_preset("klt_only").keypoint_max_motion_deg, 0.0);
  // The corner fallback is realtime's; paper and klt_only detect as before.
  EXPECT_EQ(realtime.corner_fallback_below, 30);
  EXPECT_EQ(make_preset("paper").corner_fallback_below, 0);
  EXPECT_EQ(make_preset("klt_only").corner_fallback_below, 0);
  bad = realtime;
  bad.corner_fallback_below = -1;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
  bad = realtime;
  bad.corner_fallback_quality_level = 0.0;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace kct
