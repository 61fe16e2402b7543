#include "klt_contour_tracker/core/tracker_params.h"
#include "klt_contour_tracker/core/check_range.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <variant>

namespace kct {
namespace {

constexpr const char* kOwner = "TrackerParams";

// One entry per field: its name and a pointer to it. Keeps set_param() and describe() in
// step with the struct without a hand-written if-chain per use.
using Field = std::variant<int TrackerParams::*, double TrackerParams::*, bool TrackerParams::*,
                           std::string TrackerParams::*, std::uint32_t TrackerParams::*>;
const std::vector<std::pair<const char*, Field>>& fields() {
  static const std::vector<std::pair<const char*, Field>> table = {
#define KCT_FIELD(name) {#name, &TrackerParams::name}
      KCT_FIELD(max_keypoints), KCT_FIELD(corner_quality_level), KCT_FIELD(corner_min_distance_px),
      KCT_FIELD(corner_fallback_below), KCT_FIELD(corner_fallback_quality_level),
      KCT_FIELD(klt_window_px), KCT_FIELD(klt_pyramid_levels), KCT_FIELD(klt_forward_backward_px),
      KCT_FIELD(klt_illumination_window_px), KCT_FIELD(klt_max_image_width_px),
      KCT_FIELD(ransac_reprojection_px), KCT_FIELD(ransac_iterations), KCT_FIELD(klt_min_points),
      KCT_FIELD(klt_min_inlier_ratio), KCT_FIELD(redetect_ratio), KCT_FIELD(redetect_interval_frames),
      KCT_FIELD(redetect_max_reprojection_increase_px),
      KCT_FIELD(keypoint_max_motion_diameters), KCT_FIELD(keypoint_max_motion_deg),
      KCT_FIELD(keypoint_prior_diameters), KCT_FIELD(keypoint_prior_deg),
      KCT_FIELD(keypoint_mask_erosion_px), KCT_FIELD(motion_model),
      KCT_FIELD(motion_velocity_smoothing), KCT_FIELD(motion_error_smoothing),
      KCT_FIELD(klt_predicted_flow), KCT_FIELD(keypoint_motion_gate_sigmas),
      KCT_FIELD(motion_prior_weight), KCT_FIELD(region_weight),
      KCT_FIELD(region_line_half_length_px), KCT_FIELD(region_line_spacing_px),
      KCT_FIELD(region_band_px), KCT_FIELD(region_learning_rate),
      KCT_FIELD(color_search), KCT_FIELD(color_learn_interval_frames),
      KCT_FIELD(color_lost_ratio), KCT_FIELD(color_contour_veto_ratio),
      KCT_FIELD(color_keypoint_veto_inliers), KCT_FIELD(color_keypoint_veto_inlier_ratio),
      KCT_FIELD(color_vanished_ratio),
      KCT_FIELD(color_recover_ratio), KCT_FIELD(color_recover_min_visible),
      KCT_FIELD(extrapolated_good_frames), KCT_FIELD(trusted_depth_ratio),
      KCT_FIELD(color_accept_ratio),
      KCT_FIELD(color_search_placements), KCT_FIELD(color_search_rotation_deg),
      KCT_FIELD(color_search_refined), KCT_FIELD(color_search_mesh_error_diameters),
      KCT_FIELD(hypothesis_mesh_error_diameters),
      KCT_FIELD(color_search_reach_diameters),
      KCT_FIELD(color_confirm_ratio), KCT_FIELD(drop_unconfirmed_anchors),
      KCT_FIELD(track_while_lost), KCT_FIELD(repeat_recover_diameters), KCT_FIELD(repeat_recover_deg),
      KCT_FIELD(feature_relocalization), KCT_FIELD(relocalization_override_inliers),
      KCT_FIELD(relocalization_while_tracking), KCT_FIELD(relocalization_interval_frames),
      KCT_FIELD(relocalization_below_correlation), KCT_FIELD(relocalization_doubt_whole_frame),
      KCT_FIELD(rotation_check_deg), KCT_FIELD(check_while_lost), KCT_FIELD(rotation_check_frames),
      KCT_FIELD(rotation_check_margin), KCT_FIELD(texture_check_margin),
      KCT_FIELD(texture_check_step_deg), KCT_FIELD(texture_check_every_frame),
      KCT_FIELD(plain_surface_keypoint_scale),
      KCT_FIELD(texture_shift_search_below), KCT_FIELD(texture_align_below),
      KCT_FIELD(surface_hold_correlation), KCT_FIELD(surface_recover_correlation),
      KCT_FIELD(extrapolated_search_ratio), KCT_FIELD(extrapolated_accept_margin),
      KCT_FIELD(tracked_search_ratio), KCT_FIELD(tracked_search_surface_drop),
      KCT_FIELD(occlusion_mask_radius_px),
      KCT_FIELD(occlusion_mask_frames),
      KCT_FIELD(refine), KCT_FIELD(sharp_edge_angle_deg), KCT_FIELD(icosphere_subdivisions),
      KCT_FIELD(visibility_resolution_px), KCT_FIELD(visibility_cache_dir),
      KCT_FIELD(contour_sample_spacing_px), KCT_FIELD(blur_sigma_px), KCT_FIELD(contour_chroma_weight),
      KCT_FIELD(contour_chroma_plain_only),
      KCT_FIELD(final_hops),
      KCT_FIELD(hops_budget), KCT_FIELD(min_hops_cap), KCT_FIELD(max_hops_without_improvement_cap),
      KCT_FIELD(max_hops_cap), KCT_FIELD(max_reprojection_increase_px),
      KCT_FIELD(extrapolated_rotation_bound_deg), KCT_FIELD(extrapolated_axial_bound),
      KCT_FIELD(extrapolated_lateral_bound), KCT_FIELD(hop_rotation_deg), KCT_FIELD(hop_translation),
      KCT_FIELD(metropolis_temperature), KCT_FIELD(slsqp_max_evaluations), KCT_FIELD(random_seed),
      KCT_FIELD(max_image_pixels),
      KCT_FIELD(optimizer), KCT_FIELD(pyramid_levels), KCT_FIELD(pyramid_min_object_px),
      KCT_FIELD(iterations_per_level),
      KCT_FIELD(contour_weight), KCT_FIELD(keypoint_weight), KCT_FIELD(keypoint_sigma_px),
      KCT_FIELD(shift_search_diameters), KCT_FIELD(shift_search_coarse_to_fine),
      KCT_FIELD(max_step_px),
      KCT_FIELD(num_threads),
#undef KCT_FIELD
  };
  return table;
}

template <typename T>
T parse(const std::string& name, const std::string& text) {
  if constexpr (std::is_same_v<T, bool>) {
    if (text == "true" || text == "1") return true;
    if (text == "false" || text == "0") return false;
    throw std::invalid_argument("TrackerParams." + name + ": '" + text + "' is not true/false");
  } else {
    return parse_number<T>(kOwner, name, text);
  }
}

}  // namespace

void set_param(TrackerParams& params, const std::string& name, const std::string& value) {
  for (const auto& [field_name, field] : fields()) {
    if (name != field_name) continue;
    std::visit(
        [&](auto member) {
          using T = std::decay_t<decltype(params.*member)>;
          if constexpr (std::is_same_v<T, std::string>)
            params.*member = value;
          else
            params.*member = parse<T>(name, value);
        },
        field);
    return;
  }
  throw std::invalid_argument("unknown tracker parameter '" + name + "'");
}

std::vector<std::pair<std::string, std::string>> describe(const TrackerParams& params) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [field_name, field] : fields()) {
    std::ostringstream text;
    std::visit([&](auto member) { text << std::boolalpha << params.*member; }, field);
    out.emplace_back(field_name, text.str());
  }
  return out;
}

void TrackerParams::validate() const {
  check_range(kOwner, "max_keypoints", max_keypoints, 8, 100000);
  check_range(kOwner, "corner_quality_level", corner_quality_level, 1e-6, 1.0);
  check_range(kOwner, "corner_min_distance_px", corner_min_distance_px, 0.0, 1000.0);
  check_range(kOwner, "corner_fallback_below", corner_fallback_below, 0, 100000);
  check_range(kOwner, "corner_fallback_quality_level", corner_fallback_quality_level, 1e-6, 1.0);
  check_range(kOwner, "klt_window_px", klt_window_px, 5, 201);
  if (klt_window_px % 2 == 0)
    throw std::invalid_argument("TrackerParams.klt_window_px must be odd");
  check_range(kOwner, "klt_pyramid_levels", klt_pyramid_levels, 0, 8);
  check_range(kOwner, "klt_forward_backward_px", klt_forward_backward_px, 0.01, 100.0);
  check_range(kOwner, "klt_illumination_window_px", klt_illumination_window_px, 0, 501);
  check_range(kOwner, "klt_max_image_width_px", klt_max_image_width_px, 0, 100000);
  check_range(kOwner, "ransac_reprojection_px", ransac_reprojection_px, 0.1, 100.0);
  check_range(kOwner, "ransac_iterations", ransac_iterations, 1, 100000);
  check_range(kOwner, "klt_min_points", klt_min_points, 4, 100000);
  check_range(kOwner, "klt_min_inlier_ratio", klt_min_inlier_ratio, 0.0, 1.0);
  check_range(kOwner, "redetect_ratio", redetect_ratio, 0.0, 1.0);
  check_range(kOwner, "redetect_interval_frames", redetect_interval_frames, 0, 1000000);
  check_range(kOwner, "redetect_max_reprojection_increase_px", redetect_max_reprojection_increase_px, 0.0,
              1e6);
  check_range(kOwner, "keypoint_max_motion_diameters", keypoint_max_motion_diameters, 0.0, 1e3);
  check_range(kOwner, "keypoint_max_motion_deg", keypoint_max_motion_deg, 0.0, 180.0);
  check_range(kOwner, "keypoint_prior_diameters", keypoint_prior_diameters, 0.0, 1e3);
  check_range(kOwner, "keypoint_prior_deg", keypoint_prior_deg, 1e-3, 180.0);
  check_range(kOwner, "keypoint_mask_erosion_px", keypoint_mask_erosion_px, 0, 100);
  check_range(kOwner, "color_learn_interval_frames", color_learn_interval_frames, 1, 100000);
  check_range(kOwner, "color_lost_ratio", color_lost_ratio, 0.0, 1.0);
  check_range(kOwner, "color_contour_veto_ratio", color_contour_veto_ratio, 0.0, 10.0);
  check_range(kOwner, "color_keypoint_veto_inliers", color_keypoint_veto_inliers, 0, 100000);
  check_range(kOwner, "color_keypoint_veto_inlier_ratio", color_keypoint_veto_inlier_ratio, 0.0, 1.0);
  check_range(kOwner, "color_vanished_ratio", color_vanished_ratio, 0.0, 1.0);
  check_range(kOwner, "color_recover_ratio", color_recover_ratio, 0.0, 1.0);
  check_range(kOwner, "color_recover_min_visible", color_recover_min_visible, 0.0, 1.0);
  check_range(kOwner, "extrapolated_good_frames", extrapolated_good_frames, -1, 1000);
  if (trusted_depth_ratio != 0.0)
    check_range(kOwner, "trusted_depth_ratio", trusted_depth_ratio, 1.01, 100.0);
  check_range(kOwner, "repeat_recover_diameters", repeat_recover_diameters, 0.0, 1.0);
  check_range(kOwner, "repeat_recover_deg", repeat_recover_deg, 0.0, 180.0);
  check_range(kOwner, "color_accept_ratio", color_accept_ratio, 0.0, 1.0);
  check_range(kOwner, "color_search_placements", color_search_placements, 1, 5);
  check_range(kOwner, "color_search_rotation_deg", color_search_rotation_deg, 0.0, 90.0);
  check_range(kOwner, "color_search_refined", color_search_refined, 0, 1000);
  check_range(kOwner, "color_search_mesh_error_diameters", color_search_mesh_error_diameters, 0.0,
              0.05);
  check_range(kOwner, "hypothesis_mesh_error_diameters", hypothesis_mesh_error_diameters, 0.0, 0.05);
  check_range(kOwner, "color_search_reach_diameters", color_search_reach_diameters, 0.0, 100.0);
  check_range(kOwner, "color_confirm_ratio", color_confirm_ratio, 0.0, 1.0);
  check_range(kOwner, "motion_velocity_smoothing", motion_velocity_smoothing, 1e-6, 1.0);
  check_range(kOwner, "motion_error_smoothing", motion_error_smoothing, 1e-6, 1.0);
  check_range(kOwner, "keypoint_motion_gate_sigmas", keypoint_motion_gate_sigmas, 0.0, 1000.0);
  check_range(kOwner, "motion_prior_weight", motion_prior_weight, 0.0, 1e6);
  check_range(kOwner, "region_weight", region_weight, 0.0, 1e6);
  check_range(kOwner, "region_line_half_length_px", region_line_half_length_px, 2, 100);
  check_range(kOwner, "region_line_spacing_px", region_line_spacing_px, 0.5, 100.0);
  check_range(kOwner, "region_band_px", region_band_px, 1, 100);
  check_range(kOwner, "region_learning_rate", region_learning_rate, 1e-6, 1.0);
  check_range(kOwner, "sharp_edge_angle_deg", sharp_edge_angle_deg, 0.0, 180.0);
  check_range(kOwner, "icosphere_subdivisions", icosphere_subdivisions, 0, 6);
  check_range(kOwner, "visibility_resolution_px", visibility_resolution_px, 16, 4096);
  check_range(kOwner, "contour_sample_spacing_px", contour_sample_spacing_px, 0.1, 100.0);
  check_range(kOwner, "blur_sigma_px", blur_sigma_px, 0.0, 20.0);
  check_range(kOwner, "contour_chroma_weight", contour_chroma_weight, 0.0, 10.0);
  check_range(kOwner, "final_hops", final_hops, 0, 10000);
  check_range(kOwner, "hops_budget", hops_budget, 1.0, 1e12);
  check_range(kOwner, "min_hops_cap", min_hops_cap, 0, 100000);
  check_range(kOwner, "max_hops_without_improvement_cap", max_hops_without_improvement_cap, 1, 100000);
  check_range(kOwner, "max_hops_cap", max_hops_cap, 1, 100000);
  if (min_hops_cap > max_hops_cap)
    throw std::invalid_argument("TrackerParams.min_hops_cap must be <= max_hops_cap");
  check_range(kOwner, "max_reprojection_increase_px", max_reprojection_increase_px, 0.0, 1000.0);
  check_range(kOwner, "extrapolated_rotation_bound_deg", extrapolated_rotation_bound_deg, 0.0, 180.0);
  check_range(kOwner, "extrapolated_axial_bound", extrapolated_axial_bound, 0.0, 10.0);
  check_range(kOwner, "extrapolated_lateral_bound", extrapolated_lateral_bound, 0.0, 10.0);
  check_range(kOwner, "hop_rotation_deg", hop_rotation_deg, 0.0, 180.0);
  check_range(kOwner, "hop_translation", hop_translation, 0.0, 10.0);
  check_range(kOwner, "metropolis_temperature", metropolis_temperature, 1e-9, 1e9);
  check_range(kOwner, "slsqp_max_evaluations", slsqp_max_evaluations, 1, 1000000);
  check_range(kOwner, "max_image_pixels", max_image_pixels, 32 * 32, 16384 * 16384);
  if (optimizer != "basin_hopping" && optimizer != "coarse_to_fine")
    throw std::invalid_argument("TrackerParams.optimizer = '" + optimizer.substr(0, 40) +
                                "' is not one of basin_hopping, coarse_to_fine");
  check_range(kOwner, "pyramid_levels", pyramid_levels, 1, 6);
  check_range(kOwner, "pyramid_min_object_px", pyramid_min_object_px, 0.0, 10000.0);
  check_range(kOwner, "iterations_per_level", iterations_per_level, 1, 1000);
  check_range(kOwner, "relocalization_below_correlation", relocalization_below_correlation, 0.0, 1.0);
  check_range(kOwner, "relocalization_override_inliers", relocalization_override_inliers, 6, 100000);
  check_range(kOwner, "relocalization_interval_frames", relocalization_interval_frames, 1, 1000);
  check_range(kOwner, "rotation_check_deg", rotation_check_deg, 0.0, 90.0);
  check_range(kOwner, "rotation_check_frames", rotation_check_frames, 1, 1000);
  check_range(kOwner, "rotation_check_margin", rotation_check_margin, 0.0, 10.0);
  check_range(kOwner, "texture_check_margin", texture_check_margin, 0.0, 2.0);
  check_range(kOwner, "texture_check_step_deg", texture_check_step_deg, 1.0, 180.0);
  check_range(kOwner, "plain_surface_keypoint_scale", plain_surface_keypoint_scale, 0.0, 1.0);
  check_range(kOwner, "texture_shift_search_below", texture_shift_search_below, 0.0, 1.0);
  check_range(kOwner, "texture_align_below", texture_align_below, 0.0, 1.0);
  check_range(kOwner, "surface_hold_correlation", surface_hold_correlation, 0.0, 1.0);
  check_range(kOwner, "surface_recover_correlation", surface_recover_correlation, 0.0, 1.0);
  check_range(kOwner, "extrapolated_search_ratio", extrapolated_search_ratio, 0.0, 2.0);
  check_range(kOwner, "tracked_search_ratio", tracked_search_ratio, 0.0, 2.0);
  check_range(kOwner, "tracked_search_surface_drop", tracked_search_surface_drop, 0.0, 2.0);
  check_range(kOwner, "extrapolated_accept_margin", extrapolated_accept_margin, 0.0, 2.0);
  check_range(kOwner, "occlusion_mask_radius_px", occlusion_mask_radius_px, 0.0, 500.0);
  check_range(kOwner, "occlusion_mask_frames", occlusion_mask_frames, 1, 100);
  check_range(kOwner, "contour_weight", contour_weight, 0.0, 1e6);
  check_range(kOwner, "keypoint_weight", keypoint_weight, 0.0, 1e6);
  check_range(kOwner, "keypoint_sigma_px", keypoint_sigma_px, 0.01, 1000.0);
  check_range(kOwner, "shift_search_diameters", shift_search_diameters, 0.0, 2.0);
  check_range(kOwner, "max_step_px", max_step_px, 0.0, 1e4);
  check_range(kOwner, "num_threads", num_threads, 1, 64);
}

std::vector<std::string> preset_names() { return {"realtime", "paper", "klt_only"}; }

TrackerParams make_preset(const std::string& name) {
  TrackerParams params;  // the defaults are the paper's values
  if (name == "paper") return params;
  if (name == "realtime") {
    params.optimizer = "coarse_to_fine";
    params.num_threads = 2;
    // Anchors are kept until they thin out (as klt_only): re-anchoring on every refined pose
    // turns each frame's small refinement error into drift (measured: chest xy_s5, 60 frames,
    // AUC 6.6 with re-detection every frame, 18.8 without).
    params.redetect_interval_frames = 0;
    params.klt_max_image_width_px = 1000;
    // 642 viewpoints instead of 2562: the visibility table of a 150k-face mesh builds 4x faster
    // (issue 10: <= 5 s on first start); same AUC on the bike (19.67 / 18.43 vs 19.57 / 18.40).
    params.icosphere_subdivisions = 3;
    // Untextured objects whose inner corners are faint get them all the same (see the field):
    // Castle-simu 18.91 -> 19.38 AUC; both hard sets from 5 initial poses 12.33 -> 12.28 mean
    // AUC (unchanged).
    params.corner_fallback_below = 30;
    // A PnP pose more than 25 deg or half a diameter away from the last pose is a RANSAC
    // failure on few keypoints, not hand-held motion (<= 8 deg / 30 mm a frame).
    params.keypoint_max_motion_deg = 25.0;
    params.keypoint_max_motion_diameters = 0.5;
    params.color_search = true;
    // Hard section, 24 sequences: (lost 0.4, accept 0.6, 2 placements, 20 deg) 10.51 AUC;
    // these 10.78.
    params.color_lost_ratio = 0.6;
    params.color_accept_ratio = 0.8;
    params.color_search_placements = 3;
    params.color_search_rotation_deg = 30.0;
    // Of its 21 placements and turns, the 8 of best colour contrast are refined: dev loop
    // (both hard sets, 5 draws) 14.30 against 14.29 for all 21 (+0.02 +- 0.13), lost frames
    // about 10 % faster.
    params.color_search_refined = 8;
    // The colour model's silhouettes come from the mesh simplified within 0.1 % of its
    // diameter (at most 0.25 px at the search's working size): the 150k-face bike 4.9k faces.
    params.color_search_mesh_error_diameters = 0.001;
    // ... and the hypotheses of the searches and checks are refined on it (contour extraction
    // over every face was a third of the bike's searching frames): dev loop 14.68 -> 14.74,
    // +0.06 +- 0.17 (107 of 240 runs change, 55 up); slow section unchanged.
    params.hypothesis_mesh_error_diameters = 0.001;
    // A weaker placement (>= 0.5 x the level) is taken when two frames agree on it: hard
    // section 11.05 -> 11.25 AUC (occlusion 3.44 -> 3.78, the chest behind the occluder
    // 1.75 -> 4.12: re-acquired after blur instead of never).
    params.color_confirm_ratio = 0.5;
    // The colour's loss verdict is overruled while the contour energy stays at >= 0.85 x its
    // level and the contrast above 0.15 x its level: hard section 11.25 -> 11.15 AUC, a second
    // hard set of 24 other seeds 10.07 -> 10.83 (false losses of good tracks under shadows,
    // each followed by a jump to an own-colour distractor).
    params.color_contour_veto_ratio = 0.85;
    // ... and while >= 100 KLT inliers at a ratio >= 0.95 agree: the OPT-style flash on the
    // 1080p can (30 frames) 13.73 -> 19.14 AUC, the second hard set 10.83 -> 11.01, the hard
    // section unchanged (11.14).
    params.color_keypoint_veto_inliers = 100;
    // ... at a ratio >= 0.9 rather than 0.95: an occluder sliding over a well-tracked object
    // costs a few inliers at its edge (hard2 chest occlusion: 231 of 244, 0.95 -> 0.90, 2 mm
    // off) while it lowers the outline's contrast; at 0.95 the track was declared lost and the
    // re-acquisition jumped 0.8 diameters away. Both hard sets from 5 initial poses (dev_loop.py,
    // 240 runs) 12.92 -> 12.95 mean AUC, paired +0.03 +- 0.04: 5 runs change, 4 up (hard2 chest
    // occlusion +3.6 / +4.0), 1 down (hard2 can sensor -0.3); occlusion 9.77 -> 9.97. With 50
    // inliers as well: +0.01 +- 0.03, 14 runs change, 8 down.
    params.color_keypoint_veto_inlier_ratio = 0.9;
    // While lost, a frame recovers only at >= 0.5 x the colour level with >= half its silhouette
    // in the image (the vetoes above do not apply: a static distractor keeps its outline and
    // keypoints): both hard sets from 5 initial poses 12.87 -> 12.92 mean AUC, paired
    // +0.06 +- 0.08 (6 of 240 runs change, 5 up: hard castle occlusion +8.2 / +2.6, hard2 can
    // leave +0.8 / +1.0 / +2.0; hard2 castle clutter -0.5); re-acquired right 16 of 98 -> 16 of
    // 94. 0.75 x the level: 12.77 (-0.09), 11 of 93.
    params.color_recover_ratio = 0.5;
    params.color_recover_min_visible = 0.5;
    // At most 3 frames in a row that KLT failed on are good (the pose then comes from the contour
    // alone): long section (300 frames, 8 sequences) good-but-wrong frames 1223 -> 1005 of 2400,
    // AUC unchanged (7.58; from 5 initial poses 7.76 -> 7.75, paired -0.01 +- 0.09),
    // bad-but-right frames unchanged (24); four longer sequences
    // (400-600 frames) 6.25 -> 7.29 mean AUC (chest behind a moving occluder 3.80 -> 7.96).
    // Both hard sets from 5 initial poses (dev loop, 240 runs): no run changes (80 frames: no
    // such run of wrong holds). Over 11 of these long sequences (single runs, chaotic): off
    // 7.50, 3: 7.88; 0: 7.83 (a held can in clutter 17.30 -> 14.83); 1, 2, 5: 7.08, 7.58, 7.71.
    params.extrapolated_good_frames = 3;
    // The depth range a pose may take is 1/2-2x the trusted depth (the given pose's, then that of
    // every good frame but the first 30 after a re-acquisition), and the colour search's depths
    // are clipped into it: a find 3-4x too deep (the chest's own print after an occluder) was
    // held, and each later search's depths, relative to it, went deeper still. Long section
    // from 5 initial poses (dev_loop.py run --long, 40 runs) 7.75 -> 8.49, paired +0.75 +- 0.40,
    // 7 runs up (castle mixed +2.8 to +5.4 in every draw), none down; re-acquired right within
    // 10 frames of being visible 8 of 122 -> 14 of 109.
    params.trusted_depth_ratio = 2.0;
    // Anchors laid after a KLT failure are kept only when the session judges the frame good:
    // hard section 11.14 -> 11.20 AUC, the second hard set 11.01 -> 11.38.
    params.drop_unconfirmed_anchors = true;
    // Keypoints are re-anchored on the refined pose whenever they thin out, unless it moved the
    // KLT inliers' mean reprojection error by more than 2 px (0.5 in `paper`): after a blurred
    // frame or a re-acquisition the contour corrects the pose and the new anchors follow it
    // (hard section: 9.89 -> 10.38 AUC).
    params.redetect_max_reprojection_increase_px = 2.0;
    // When KLT fails, the refinement also starts from the best image-plane shift within 0.8
    // object diameters (coarsest level): hard section 10.62 -> 10.86 mean AUC.
    params.shift_search_diameters = 0.8;
    // ... scored coarse-to-fine (every second shift, then around the best 8): a lost frame's
    // shift searches take a third of its time. Both hard sets from 5 initial poses (240 runs)
    // 13.59 -> 13.56 mean AUC, paired -0.02 +- 0.06 (unchanged); live at 30 Hz (hard set, 3
    // initial poses, 72 runs) 12.16 -> 12.72, +0.57 +- 0.18 (occlusion 5.86 -> 7.93): fewer
    // frames dropped while lost.
    params.shift_search_coarse_to_fine = true;
    params.max_step_px = 8.0;  // a safeguard: see the field
    // For 5 frames after KLT failed or a re-acquisition, turns of +-15 deg are tried against the
    // held rotation (see the field): hard + second hard set 11.29 -> 11.39 mean AUC.
    params.rotation_check_deg = 15.0;
    // While lost, the pipeline's pose is not checked (see the field): both hard sets from 5
    // initial poses (240 runs) 14.69 -> 14.68, paired -0.01 +- 0.02 (2 runs change); median lost
    // frame of the hard occlusion and leave sequences 10-25 % lower (e.g. hard/can/leave 42 ->
    // 32 ms, hard/toy/occlusion 57 -> 44 ms; 5 interleaved runs, alone on the machine).
    params.check_while_lost = false;
    // In the same window, turns about the object's own axes are checked against the surface
    // colours learned at the initial pose (see the field): hard + second hard set 11.47 -> 12.00
    // mean AUC; of 12 corrections 9 lowered the rotation error (136.7 -> 3.2, 48.2 -> 2.6,
    // 24.7 -> 5.8 deg ...), one raised it (castle, 26.7 -> 32.5), two were on lost tracks.
    params.texture_check_margin = 0.2;
    params.texture_check_every_frame = true;
    // A held pose whose printed surface correlates below 0.3 is searched for by shifts (see
    // the field): photo section from 5 initial poses +0.78 +- 0.27 AUC paired, every draw higher
    // (photo/chest/handheld 5.05 -> 18.73: held 0.2 diameters off after a fast move).
    params.texture_shift_search_below = 0.3;
    // A held pose whose surface correlates below 0.8 is aligned to it (turned and shifted, see
    // the field). At 0.3: both hard sets from 5 initial poses +0.15 +- 0.20 AUC paired (4 of 5
    // draws higher), photo -0.07 +- 0.11. 0.3 -> 0.8: both hard sets 12.24 -> 12.55 mean AUC,
    // paired -0.11 +0.36 +0.35 +0.50 +0.42; photo 15.98 -> 16.22, paired +0.03 +0.62 +0.28
    // +0.35 -0.03 (1.0 gives the same poses: a take needs the held correlation + 0.2).
    params.texture_align_below = 0.8;
    // Dev loop (both hard sets, 5 initial poses, 240 runs): 12.95 -> 12.96, 4 runs up (hard
    // chest occlusion +0.5 to +1.0), none down; 0.5: one run -4.95 (a wrong pose held).
    params.surface_hold_correlation = 0.7;
    // When KLT failed and the refined pose's colour contrast fell below 0.25 x its level, the
    // colour search runs at once (see the field): hard + second hard set 12.19 -> 12.35 mean
    // AUC (0.1: 12.35, 0.4: 12.36).
    params.extrapolated_search_ratio = 0.25;
    // ... and its find is taken when it beats the held pose's contrast by 0.3 x the level (see
    // the field): both hard sets from 5 initial poses 12.55 -> 12.63 mean AUC, paired
    // +0.09 +- 0.15: 13 of the 240 runs change, 10 up (hard castle occlusion +8.0, hard chest
    // sensor +6.2 / +5.3, hard2 can handheld +4.6) and 3 down (hard chest leave -4.9: lost either
    // way); 0.5 gives the same poses.
    params.extrapolated_accept_margin = 0.3;
    // A KLT-tracked frame whose colour contrast fell below 0.8 x its level is searched too, and
    // the find is taken when it beats the held pose (see the field): both hard sets from 5 initial
    // poses +0.76 +- 0.19 AUC paired (every draw higher), photo +0.30 +- 0.32.
    params.tracked_search_ratio = 0.8;
    // ... but not a find whose surface pattern disagrees where the held pose's agrees (see the
    // field): photo section 16.36 -> 16.76 mean AUC (can hand-held 8.28 -> 13.12); both hard sets
    // from 5 initial poses +0.03 +- 0.07 (2 runs change); mismatch from 3 +0.12 +- 0.02.
    params.tracked_search_surface_drop = 0.3;
    // The keypoints of an object without a colour pattern weigh 0.3 x as much (see the field):
    // both hard sets from 5 initial poses (dev_loop.py, 240 runs) 13.04 -> 13.48 mean AUC,
    // paired +0.43 +- 0.40 (toy and castle +0.71 +- 0.54, every draw higher; 0.5: +0.48, 0.1:
    // +0.67 +- 1.12); with the model 3 % off (144 runs) +0.26 +- 0.47; photo section 16.76 ->
    // 17.20 (toy light 13.83 -> 16.76). For every object (keypoint_weight 0.03) the printed can
    // lost (photo hand-held 13.12 -> 7.67).
    params.plain_surface_keypoint_scale = 0.3;
    // The contour energy of an object without a colour pattern also reads the chromaticity's
    // edges (see the fields): a curved object's shaded rim no longer pulls its outline inside.
    // Both hard sets from 5 initial poses (240 runs) 13.56 -> 14.21, paired +0.65 +- 0.29, every
    // draw higher (leave 9.93 -> 11.88, occlusion 10.14 -> 10.52; toy +2.17, castle +0.28); with
    // the model 3 % off (144 runs) 12.04 -> 12.82, +0.78 +- 0.34, every draw higher. For every
    // object: +0.36 +- 0.15 (the printed can -0.89: its colour stripes run along its outline).
    params.contour_chroma_weight = 1.0;
    params.contour_chroma_plain_only = true;
    // The refinement starts no coarser than where the object is 40 px across (see the field):
    // far section (8 sequences, 0.9-1.3 m) 4.50 -> 7.21 mean AUC; both hard sets from 5 initial
    // poses (240 runs, 106 change: the can and the toy at the far end of 0.35-0.6 m) +0.01 +-
    // 0.35; with the model 3 % off (144 runs) 11.62 -> 12.12, +0.50 +- 0.16, every draw higher;
    // 30 px: far 6.41; one level for every object: far 7.35.
    params.pyramid_min_object_px = 40.0;
    // While lost, a frame the searches did not re-acquire is tracked on from where the last one
    // ended, not refined around the last good pose (see the field): both hard sets from 5
    // initial poses (240 runs) 13.49 -> 13.55, paired +0.06 +- 0.10; losses re-acquired right
    // within 10 frames of being visible 4 of 92 -> 11 of 91; frames spent lost 1714 -> 1454.
    // With the model 3 % off (144 runs) -0.07 +- 0.20, re-acquired right 9 of 61 -> 6 of 60.
    params.track_while_lost = true;
    // While lost, a find at the previous frame's find (0.05 diameters, 5 deg) counts as good
    // (see the field): both hard sets from 5 initial poses (240 runs) -0.03 +- 0.08 mean AUC,
    // losses re-acquired right within 10 frames of being visible 23 of 136 -> 31 of 137.
    // Within a frame's hand-held motion (0.2 diameters, 10 deg) rather than 0.05 / 5: a
    // hand-held toy back in the image was found right on every frame from the first but 20-30
    // mm a frame apart, and recovered 12 frames later (hard2/toy/leave, every draw). Both hard
    // sets from 5 initial poses (240 runs) 14.30 -> 14.42, paired +0.12 +- 0.14, re-acquired
    // right 31 of 115 -> 38 of 112; long section +0.16 +- 0.26 (5 runs up, 1 down); slow
    // section unchanged.
    params.repeat_recover_diameters = 0.2;
    params.repeat_recover_deg = 10.0;
    // Re-acquisition keeps to 0.25 diameters a frame around the last good pose (see the field):
    // photo section from 5 initial poses +0.59 +- 0.26 AUC (every draw higher: a loss no longer
    // re-acquired on a clutter can wearing the can's texture 2.8 diameters away); both hard sets
    // -0.02 +- 0.05 (unchanged).
    params.color_search_reach_diameters = 0.25;
    // Contour points within 6 px of anchors whose KLT track failed in the last 2 frames are left
    // out of the energy (see the field): both hard sets from 5 initial poses 12.63 -> 12.87 mean
    // AUC, paired +0.23 +- 0.33 (per draw +0.23 +0.68 -0.19 +0.05 +0.39): occlusion 8.80 -> 9.50,
    // handheld 15.05 -> 15.79, lighting 14.90 -> 15.38, leave 10.24 -> 9.76, re-acquired right
    // 19 of 103 -> 16 of 98. 12 px / 5 frames was worse (occlusion + clutter + handheld, draws
    // 0-1: -0.85), 12 px / 1 frame unchanged (+0.12).
    params.occlusion_mask_radius_px = 6.0;
    params.occlusion_mask_frames = 2;
    // While lost, ORB features of the given pose's keyframe are matched over the frame before
    // the colour search (see the fields); nothing while tracking. Both hard sets from 5 initial
    // poses (dev_loop.py, 240 runs) 12.96 -> 13.00 mean AUC, paired +0.04 +- 0.01: 7 runs
    // change, all up (hard can leave +1.8 to +2.0 in every draw: re-acquired at last, where
    // the colour search took a background place of its colours; hard2 chest leave +0.6 / +0.8),
    // leave 9.84 -> 10.09, every other condition unchanged. Matched on every frame as well
    // (relocalization_while_tracking), occlusion + leave gained +0.14 +- 0.06 against +0.12 +-
    // 0.03 while lost only, with 2 of 9 changed runs down and twice the median frame time.
    params.feature_relocalization = true;
    params.relocalization_while_tracking = false;
    // ... on every second lost frame: the matching took about 20 ms of a lost frame (of
    // 80-100) and found the object on 9 of 1557 lost frames over both hard sets from 5 initial
    // poses; there 14.30 against 14.30 (-0.00 +- 0.00, 1 of 240 runs changes: -0.15).
    params.relocalization_interval_frames = 2;
    // A tracked frame of a printed object whose surface correlates below 0.2 with the learned
    // one is matched against the keyframes as well (see the field): both hard sets from 5
    // initial poses (240 runs) 14.21 -> 14.31, paired +0.10 +- 0.09, 4 runs change, all up
    // (hard chest sensor +7.2 / +7.5 / +8.3: held 40 deg off and 15 cm deeper on the chest's
    // blue front after a blurred jerk); with the model 3 % off (144 runs) 12.82 -> 12.91,
    // +0.09 +- 0.14, 3 runs change, all up.
    params.relocalization_below_correlation = 0.2;
    // ... and, not found around the held pose, over the whole frame (see the field): both hard
    // sets from 5 initial poses (240 runs) 14.61 -> 14.69, paired +0.09 +- 0.01, every draw
    // higher; 6 runs change, all up (hard can leave +4.5 to +5.1 in every draw, hard2 can leave
    // +2.4).
    params.relocalization_doubt_whole_frame = true;
    return params;
  }
  if (name == "klt_only") {
    params.refine = false;
    params.redetect_interval_frames = 0;
    params.klt_max_image_width_px = 1000;
    // 642 viewpoints instead of 2562: the visibility table of a 150k-face mesh builds 4x faster
    // (issue 10: <= 5 s on first start); same AUC on the bike (19.67 / 18.43 vs 19.57 / 18.40).
    params.icosphere_subdivisions = 3;
    return params;
  }
  std::string known;
  for (const auto& n : preset_names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown preset '" + name + "' (known: " + known + ")");
}

}  // namespace kct
