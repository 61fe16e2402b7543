#pragma once
/// \file tracker_params.h
/// Every tunable of the tracker in one struct. Defaults are the paper's values (Sec. 3 and the
/// supplement, "Implementation Settings"); values the paper does not give are marked "ours".

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace kct {

/// Parameters of the whole per-frame pipeline.
struct TrackerParams {
  // ---- Keypoints: Shi-Tomasi detection, pyramidal KLT, PnP + RANSAC (Sec. 3.1) -------------
  int max_keypoints = 400;                 ///< ours: corners detected inside the object mask
  double corner_quality_level = 0.01;      ///< ours: Shi-Tomasi quality relative to the best
  double corner_min_distance_px = 6.0;     ///< ours: minimum distance between corners, px
  /// ours: when fewer than this many corners pass `corner_quality_level` (an untextured object
  /// whose strongest corner is a silhouette corner: the faint ones inside fall below 1 % of it),
  /// corners are detected again at `corner_fallback_quality_level` (0 = never; `realtime`: 30).
  /// ViSP's Castle-simu (grey low-poly castle, 40 frames): 18.91 -> 19.38 AUC, as `paper`.
  int corner_fallback_below = 0;
  double corner_fallback_quality_level = 0.001;  ///< ours: the fallback's Shi-Tomasi quality
  int klt_window_px = 21;                  ///< ours: LK window side, px (odd)
  int klt_pyramid_levels = 3;              ///< ours: LK pyramid levels above the base
  double klt_forward_backward_px = 1.0;    ///< ours: max forward-backward error of a track, px
  /// ours: KLT runs on frames normalized to zero mean and unit variance over windows of this
  /// side, px (0 = raw frames), so that a light switched on or moved (OPT's flash and moving
  /// light groups) does not break the brightness-constancy assumption of Lucas-Kanade.
  int klt_illumination_window_px = 15;
  /// ours: frames wider than this are halved (repeatedly, at most 4 times) for KLT and corner
  /// detection; keypoints stay in full-resolution pixels (0 = never; `realtime`: 1000, so a
  /// 1920x1080 frame is tracked at 960x540).
  int klt_max_image_width_px = 0;
  double ransac_reprojection_px = 3.0;     ///< ours: RANSAC inlier threshold, px
  int ransac_iterations = 200;             ///< ours: RANSAC iterations
  int klt_min_points = 8;                  ///< paper: KLT fails below this many tracked points
  double klt_min_inlier_ratio = 0.3;       ///< paper: KLT fails below this RANSAC inlier rate
  /// ours: re-detect keypoints from the newest pose when the tracked inliers fall below this
  /// fraction of the count at the last detection.
  double redetect_ratio = 0.6;
  /// Also re-detect every N frames (0 = only when the points thin out). 1 follows the paper
  /// ("on the frames where the object pose is known, we identify 2D keypoints", Sec. 3.1): each
  /// refined pose re-anchors fresh keypoints, so KLT drift never accumulates.
  int redetect_interval_frames = 1;
  /// ours: keypoints are re-anchored on the refined pose only when the KLT inliers' mean
  /// reprojection error there exceeds the PnP pose's by at most this much, px. A refinement
  /// that lands in a wrong optimum (the energy is nearly flat between some poses) then stays a
  /// one-frame error instead of being baked into the new anchors.
  double redetect_max_reprojection_increase_px = 0.5;
  /// ours (0 = off, the paper): a PnP pose that moved the object's centre by more than this
  /// many object diameters, or rotated it by more than keypoint_max_motion_deg, from the
  /// expected pose (the motion model's prediction or the last pose) in one frame is not a
  /// preliminary pose: KLT counts as failed (a few keypoints, e.g. 6 of 10 on a small blurred
  /// object, let RANSAC pick a flipped pose 100 mm away; hand-held motion is <= 30 mm / 8 deg).
  double keypoint_max_motion_diameters = 0.0;
  double keypoint_max_motion_deg = 0.0;  ///< ours: see keypoint_max_motion_diameters (0 = off)
  /// ours (0 = off, the paper): the PnP pose becomes the most likely pose given its inliers and
  /// a Gaussian prior on the frame-to-frame motion from the expected pose, with this standard
  /// deviation of the centre's translation (object diameters) and keypoint_prior_deg of the
  /// rotation. Where the inliers fix the pose it stays; where they leave it free (11 points in
  /// one strip of a blurred can gave a pose 64 mm too close) it stays near the expected pose
  /// (pose_with_motion_prior() in keypoint_tracker.h). Off in every preset: realtime with 0.1,
  /// 2026-11-27: photo section 14.91 -> 15.34 AUC (can 9.46 -> 11.89, toy 17.19 -> 16.36; one
  /// draw), hard sections' noise draws 11.00 +- 0.34 against 11.39 +- 0.62, paired difference
  /// -0.39 +- 0.65 (not shown either way).
  double keypoint_prior_diameters = 0.0;
  double keypoint_prior_deg = 5.0;  ///< see keypoint_prior_diameters

  // ---- Cues for hand-held motion in clutter (ours, beyond the paper; off in `paper`) --------
  /// Erosion of the object's rendered mask before corner detection, px: keypoints stay strictly
  /// inside the silhouette, where the background cannot show through (paper preset: 3).
  int keypoint_mask_erosion_px = 3;
  /// Constant-velocity motion model with learned uncertainty (motion_model.h): its prediction
  /// is the KLT/PnP starting point, the pose when KLT fails (instead of the paper's two-pose
  /// extrapolation) and the refinement's expected pose.
  bool motion_model = false;
  double motion_velocity_smoothing = 0.5;  ///< weight of the newest motion in the velocity, (0, 1]
  double motion_error_smoothing = 0.3;     ///< weight of the newest error in its variance, (0, 1]
  /// With motion_model: KLT starts from the keypoints' predicted positions.
  bool klt_predicted_flow = true;
  /// With motion_model, > 0: tracks farther than this many standard deviations of the
  /// prediction (projected to px, at least 3 px) from their predicted position are dropped
  /// before PnP (unless more than half would be). 0 = off.
  double keypoint_motion_gate_sigmas = 0.0;
  /// With motion_model and the coarse_to_fine optimizer: weight of the motion prior cue
  /// (motion_prior_cost.h), 0 = off.
  double motion_prior_weight = 0.0;
  /// With the coarse_to_fine optimizer on colour frames: weight of the region (colour) cue
  /// (region_cue.h, SRT3D-style correspondence lines), 0 = off. Off in every preset: after its
  /// lines were restricted to the outer outline (2026-11-27), realtime with 0.3 scored 10.40 on
  /// the hard sections (one draw; realtime 12.35 there, 11.39 +- 0.62 over draws) and 14.53 on
  /// the photo section (realtime 14.91), with 1: 9.96 and 12.96; it renders the silhouette at
  /// every re-linearization (chest: median frame ~80 against ~20 ms).
  double region_weight = 0.0;
  int region_line_half_length_px = 12;  ///< pixels sampled on each side of the outline (level 0)
  double region_line_spacing_px = 6.0;  ///< distance between correspondence lines, px
  int region_band_px = 10;              ///< width of the bands colours are learned from, px
  double region_learning_rate = 0.2;    ///< weight of a new frame in the colour histograms, (0, 1]

  /// The tracking session's colour model (object_search.h; off in `paper` and `klt_only`): the
  /// object's colours are learned at good poses every color_learn_interval_frames; a frame whose
  /// outline separates them less than color_lost_ratio x their running contrast, or whose object
  /// is less than 10 % in the image, is a bad frame; while lost, the whole frame is searched for
  /// them and the best placement with at least color_accept_ratio x the running contrast is
  /// refined and tracked from.
  bool color_search = false;
  int color_learn_interval_frames = 3;  ///< frames between two colour learnings
  double color_lost_ratio = 0.4;        ///< bad frame below this share of the contrast level
  /// ours (0 = off): a frame below color_lost_ratio stays good while its refined contour energy
  /// is at least this share of its running level, unless its contrast is below
  /// color_vanished_ratio x the colour level (track_quality.h, ColorLossRule).
  double color_contour_veto_ratio = 0.0;
  /// ours (0 = off): ... or while KLT keeps at least this many RANSAC inliers at an inlier
  /// ratio >= color_keypoint_veto_inlier_ratio (same exception).
  int color_keypoint_veto_inliers = 0;
  double color_keypoint_veto_inlier_ratio = 0.95;  ///< see color_keypoint_veto_inliers
  double color_vanished_ratio = 0.15;   ///< see color_contour_veto_ratio
  /// ours (0 = off): while LOST, a frame counts towards recovery only when its colour contrast
  /// is at least this x the contrast level, whatever its contour energy and keypoints ...
  double color_recover_ratio = 0.0;
  /// ours (0 = off): ... and at least this share of its silhouette is inside the image
  /// (track_quality.h, ColorLossRule::recover_min_visible).
  double color_recover_min_visible = 0.0;
  /// ours (-1 = off): at most this many frames in a row that KLT failed on (extrapolated, then
  /// refined) can be good; later ones are bad until KLT tracks again, so a track held by the
  /// contour alone is declared lost and re-acquired (track_quality.h,
  /// ColorLossRule::extrapolated_good_frames).
  int extrapolated_good_frames = -1;
  /// ours (0 = off, else > 1): a pose whose object centre is deeper than this x the trusted
  /// depth, or nearer than the trusted depth / this, is bad; the colour search's depths are
  /// relative to the last good pose's depth clipped into that range. The trusted depth: the
  /// given pose's, then each good TRACKING frame's, except for the first 30 good frames after
  /// a re-acquisition (a wrong find and the poses held from it do not move the range).
  double trusted_depth_ratio = 0.0;
  double color_accept_ratio = 0.6;      ///< re-acquire from a placement above this share
  /// Re-acquisition refines the best color_search_placements colour placements, each also
  /// turned by +-color_search_rotation_deg about the camera axes (0: not turned), and the last
  /// good pose, and continues from the refined pose with the best colour contrast.
  int color_search_placements = 2;
  double color_search_rotation_deg = 20.0;
  /// ours (0 = all; realtime 8): of the placements and their turns, only this many, those with
  /// the best colour contrast before refinement, are refined (the last good pose and the last
  /// frame's are always): a lost frame refined 23 hypotheses at about 1 ms each.
  int color_search_refined = 0;
  /// ours (0 = the mesh as given; realtime 0.001): the colour model's silhouettes (learning,
  /// search, scoring) are drawn from the mesh simplified as far as it stays within this share of
  /// its diameter (ObjectSearchSettings::silhouette_error_diameters, [0, 0.05]). The refinement
  /// and everything else keep the full mesh.
  double color_search_mesh_error_diameters = 0.0;
  /// ours (0 = the mesh as given; realtime 0.001): the hypotheses of a re-acquisition or of a
  /// check (the colour search's placements, the turns of rotation_check and texture_check:
  /// Tracker::refine_hypotheses()) are refined on the mesh simplified within this share of its
  /// diameter, [0, 0.05]; the tracked frame's refinement keeps the full mesh.
  double hypothesis_mesh_error_diameters = 0.0;
  /// ours (0 = off: the whole frame; realtime 0.25): the colour search and its hypotheses keep
  /// to a disc around the last good pose's projected centre whose radius grows by this many
  /// object diameters (at the last good depth) per frame since that pose. A hand-held object
  /// moves at most ~0.25 diameters a frame; a thing of the object's colours (or texture) farther
  /// away than it could have gone is then not taken for it, while an object that left the image
  /// for a while is still searched for everywhere.
  double color_search_reach_diameters = 0.0;
  /// ours (0 = off): a re-acquisition hypothesis below color_accept_ratio but with at least this
  /// share of the contrast level is accepted when the previous frame's best hypothesis was
  /// within a quarter of the object's diameter of it (confirmed over two frames). Blur and a
  /// partial occlusion lower the contrast of the right placement (measured: 0.40-0.48 against a
  /// level of 0.63 on the chest behind the occluder), while a wrong placement rarely wins twice
  /// at the same place.
  double color_confirm_ratio = 0.0;
  /// ours (tracking session): keypoints anchored on a frame where KLT failed (at the
  /// extrapolated + refined pose) are dropped again when the session's quality monitor judges
  /// that frame bad, so that KLT never follows anchors laid on a wrong pose (they track the
  /// background or a spun copy of the object consistently, and look healthy); the next frame is
  /// refined from the contour again and anchors afresh.
  bool drop_unconfirmed_anchors = false;
  /// ours (tracking session; false = refine around the last good pose, as before): while LOST,
  /// a frame where neither the feature relocalizer nor the colour search re-acquired the object
  /// is tracked by the pipeline from where the last frame ended (KLT, extrapolation, refinement;
  /// then the session's checks of a tracked frame, e.g. extrapolated_search_ratio's search when
  /// KLT failed) instead of being refined around the last good pose with the widened search
  /// area. The last good pose is frames old: a hand-held object has moved on since (and is
  /// often still held right while blur or an occluder made its frames bad), so refining there
  /// takes a held pose away; the colour search still looks for the object on every lost frame.
  bool track_while_lost = false;
  /// ours (tracking session; 0 = off): while LOST, a re-acquired frame (the colour search's or
  /// the feature relocalizer's find, or the refinement around the last good pose) whose pose is
  /// within repeat_recover_diameters x the object's diameter (centre) and repeat_recover_deg
  /// (rotation) of the previous frame's re-acquired pose counts as good towards the recovery,
  /// whatever its quality score (color_recover_ratio and color_recover_min_visible still
  /// apply). A find has no keypoints (k = 0) and its contour energy is judged against a level
  /// learned on sharp frames before the loss: under sensor noise or blur a right find scores
  /// 0.35-0.46 for ten frames while the search finds the same place every frame.
  double repeat_recover_diameters = 0.0;
  double repeat_recover_deg = 5.0;  ///< see repeat_recover_diameters
  /// ours (tracking session, feature_relocalizer.h): ORB features of keyframes (the initial
  /// pose, then good frames from new viewpoints) anchored on the mesh; with
  /// relocalization_while_tracking each tracked frame they are matched around the tracked
  /// pose, and a PnP pose from at least
  /// relocalization_override_inliers features that disagrees with a track in doubt (KLT failed
  /// or the last frame was bad) replaces it; while lost they are matched where the object can be
  /// (its rectangle at the last good pose grown by color_search_reach_diameters' reach; the whole
  /// frame without a reach) to re-acquire. Textured objects only (an
  /// untextured one never gives enough features: the option then does nothing).
  bool feature_relocalization = false;
  int relocalization_override_inliers = 25;  ///< PnP inliers needed to replace a held track
  /// ours (tracking session; false = around the held pose only): a tracked frame in doubt by
  /// its surface (relocalization_below_correlation) whose features are not found around the
  /// held pose is matched against the keyframes over the whole frame as well. A surface that
  /// disagrees says the held pose may not be on the object at all, and then the object is
  /// anywhere: hard/can/leave, after the can left the image a blue patch 6-7 diameters away
  /// was re-acquired and held by 45 KLT inliers, its surface at 0.0-0.04, and the can, back in
  /// view, was never looked for where it was. The held pose's region is tried first: over the
  /// whole frame ORB's feature budget goes mostly to clutter (searched there alone, hard
  /// can clutter and hard2 can occlusion lost their finds: -3.4 to -4.0).
  bool relocalization_doubt_whole_frame = false;
  /// With feature_relocalization: false = features are matched only while lost (to re-acquire;
  /// keyframes then only from the given poses, since a new one must be confirmed by the
  /// tracked frame's match), which costs nothing while tracking. true = also on every tracked
  /// frame around the held pose (the matching above, and keyframes from new viewpoints): 26.2
  /// against 12.3 ms median a frame on hard/chest/handheld.
  bool relocalization_while_tracking = true;
  /// ours (realtime 2): while lost, the features are matched on the first lost frame and then
  /// on every this-many-th (1 = every lost frame): matching cost a lost frame about 20 ms and
  /// re-acquired on under 1 % of them; an object that is back stays back for the next frame.
  int relocalization_interval_frames = 1;
  /// ours (tracking session; 0 = off; needs feature_relocalization and texture checks): a
  /// tracked frame of an object with a colour pattern whose held pose's surface correlates below
  /// this with the colours learned at the initial pose (texture_check_margin's measure,
  /// [-1, 1]) is in doubt: the keyframes' features are matched around it (as with
  /// relocalization_while_tracking, on this frame only) and a pose from at least
  /// relocalization_override_inliers of them that disagrees replaces it. After a blurred jerk a
  /// search can settle on part of the object (the blue front of a chest, seen from 40 deg off
  /// and 15 cm deeper) that every other cue accepts, and KLT follows it; its surface does not
  /// correlate (measured on both hard sets: tracked frames of the can and chest correlating below
  /// 0 were 0.1 diameters off or more on 329 of 350).
  double relocalization_below_correlation = 0.0;
  /// ours (tracking session, 0 = off; needs color_search): for rotation_check_frames frames
  /// after KLT failed or the track was re-acquired, the tracked pose is also turned by
  /// +-rotation_check_deg about each camera axis through the object's centre and each turn is
  /// refined (contour only); a turn whose colour contrast beats the held pose's by
  /// rotation_check_margin x the contrast level (and passes color_accept_ratio), whose contour
  /// energy is no lower and whose centre stayed within 0.2 diameters, replaces the held pose when
  /// the same turn wins on two consecutive frames; the keypoints are then anchored afresh. It
  /// catches a rotation that anchors laid after a blurred jerk hold consistently (KLT agrees with
  /// itself at a wrong pose). Hard + second hard set (48 sequences, realtime): off 11.29 mean
  /// AUC, 15 deg 11.39 (six corrections, each lowering the rotation error, e.g. 19.6 -> 0.2 deg);
  /// 20 deg 11.45 but one correction turned a right chest 30 deg; checked on every frame (20 deg)
  /// 11.28: 4 of 14 corrections made the pose worse, and the median frame time was 6x.
  double rotation_check_deg = 0.0;
  /// ours (tracking session; realtime false): while LOST, a frame the searches did not
  /// re-acquire (track_while_lost's pipeline pose) is also put through rotation_check and
  /// texture_check. Off, a lost frame spends its time on the searches for the object, which
  /// re-acquire it, and not on correcting a pose already judged lost. (Without texture_check's
  /// correlation such a frame's tracked search has no tracked_search_surface_drop bar.)
  bool check_while_lost = true;
  int rotation_check_frames = 5;       ///< see rotation_check_deg
  double rotation_check_margin = 0.1;  ///< see rotation_check_deg
  /// ours (tracking session, 0 = off; needs color_search): the object's surface colours are
  /// learned at the initial pose (SurfaceTexture; only when they vary enough: a uniformly
  /// coloured object has no pattern). In rotation_check's window, the held pose is also turned
  /// about each of the object's own axes through its centre in steps of texture_check_step_deg;
  /// a turn whose colours correlate with the learned ones better than the held pose's by
  /// texture_check_margin wins. When the same turn wins on two consecutive frames it is refined
  /// (contour only) and replaces the held pose if it still correlates better by the margin, its
  /// contour energy is at least 0.9x the held one's, its centre stayed within 0.2 diameters and
  /// its colour contrast passes color_accept_ratio. It catches turns about a symmetry axis (a
  /// can) that no outline or colour histogram can see.
  double texture_check_margin = 0.0;
  /// ours (tracking session, 0 = off; needs color_search): on a frame where KLT failed and
  /// whose refined pose's colour contrast is below this x the contrast level, the colour
  /// search's re-acquisition runs at once on that frame, before the track is declared lost; its
  /// pose replaces the refined one when it passes color_accept_ratio (or color_confirm_ratio).
  /// A jump too fast for KLT and the shift search is found on the frame it happens.
  double extrapolated_search_ratio = 0.0;
  /// ours (0 = off): ... and its find is also taken when its contrast beats the held pose's by
  /// at least this x the contrast level and reaches color_confirm_ratio x the level (or, with
  /// that off, half the level). After a jerk the blurred object's right placement lost some
  /// contrast (measured: 0.42 at a level of 0.535, below color_accept_ratio 0.8) while the
  /// pose the contour took sits on the background (-0.26).
  double extrapolated_accept_margin = 0.0;
  /// ours (tracking session, 0 = off; needs color_search): on a frame KLT tracked whose refined
  /// pose's colour contrast is below this x the contrast level (and that rotation_check and
  /// texture_check left as it was), the colour search runs as while lost; its pose replaces the
  /// held one only when it beats the held pose: colour contrast higher by 0.2 x the level and
  /// passing color_accept_ratio, contour energy at least 0.9 x the held one's and 0.7 x the
  /// energy level. KLT's anchors can hold a wrong pose as well as a right one (after a jump they
  /// are laid on the background, which then "tracks" perfectly); the colours tell, and the
  /// search finds the object again before the loss is declared.
  double tracked_search_ratio = 0.0;
  /// ours (tracking session, 0 = off; with tracked_search_ratio and a learned surface with a
  /// colour pattern): when the held pose's surface colours correlate at least 0.5 with the
  /// learned ones, a tracked search's find must correlate no less than the held pose's minus
  /// this. The colours of a thing wearing the object's colours beside it can beat a held pose
  /// whose contrast faded (a glossy can under a moving light), while its surface does not show
  /// the object's printed pattern; KLT then holds the wrong find perfectly.
  double tracked_search_surface_drop = 0.0;
  /// ours (tracking session, 1 = off; needs texture_check_margin): when the surface learned on
  /// the initial frame (SurfaceTexture, colour frames only) shows no colour pattern
  /// (SurfaceTexture::has_color_pattern() false: a uniformly coloured or grey object), the
  /// refinement's keypoint_weight is multiplied by this for that track. Such an object's
  /// corners are its outline's and its shading's, which slide with the silhouette and the
  /// light; the contour is then the better cue. Grey frames (nothing learned) keep the weight.
  double plain_surface_keypoint_scale = 1.0;
  double texture_check_step_deg = 10.0;  ///< see texture_check_margin
  /// texture_check runs on every tracked frame, not only in rotation_check's window, when the
  /// learned surface has a colour pattern (SurfaceTexture::has_color_pattern(): printed or
  /// painted colours, not shading). Hard + second hard set: 12.00 -> 12.17 mean AUC (can
  /// 10.30 -> 10.91), median frame time of the can 7 -> 12 ms.
  bool texture_check_every_frame = false;
  /// ours (tracking session, 0 = off; needs texture_check_margin and an object whose learned
  /// surface has a colour pattern, SurfaceTexture::has_color_pattern()): when texture_check
  /// finds the held pose's surface colours correlating below this, the held pose shifted in the
  /// camera frame (laterally up to 0.25 diameters in steps of 0.05, in depth by 8 %) is scored
  /// against the learned colours (SurfaceTexture::best_shift()). A shift correlating at least
  /// max(this, the held pose's + texture_check_margin) and found again on the next such frame
  /// (within 0.15 diameters) is refined (contour only) and replaces the held pose when it still
  /// correlates that well, keeps 0.9 of the held contour energy and passes color_accept_ratio.
  /// texture_check's turns cannot correct a pose the contour holds a few centimetres off, with
  /// keypoints anchored there (the photo chest after a fast move: 0.2 diameters off for 60
  /// frames, its colours correlating at -0.1, shifted at 0.4).
  double texture_shift_search_below = 0.0;
  /// ours (tracking session, 0 = off; needs texture_check_margin and a learned surface,
  /// SurfaceTexture::ready()): on every tracked frame the held pose's surface colours are
  /// correlated with the learned ones; below this, the pose within 20 deg and 0.1 diameters of
  /// the held one whose colours correlate best is searched for (SurfaceTexture::align(), coarse
  /// to fine, at most 300 agreements), refined (contour only, no shift search) and taken when
  /// it still correlates at least max(0.5, the held pose's + texture_check_margin), keeps 0.9
  /// of the held contour energy and passes color_accept_ratio. KLT's anchors hold a pose turned
  /// 10-20 deg about no axis of the object's as firmly as the right one (the toy after an
  /// occlusion: 17 deg off for 30 frames, correlating at -0.1; aligned at 0.8); texture_check's
  /// turns about the object's axes and the shifts miss it.
  double texture_align_below = 0.0;
  /// ours (tracking session, 0 = off; needs texture_check_margin and a learned surface with a
  /// colour pattern): while TRACKING, a bad frame that KLT tracked or extrapolated whose surface
  /// colours correlate at least this with the learned ones is held: it counts neither towards
  /// the loss nor as good (no level learns from it). Blur drops the contour energy and KLT's
  /// inliers while the printed surface still matches: hard/chest/occlusion, a blurred stretch of
  /// 5 frames (energy 0.22 x its level, pose 0.03 diameters off, surface at 0.75) was declared
  /// lost. Over both hard sets, bad-judged tracked frames at >= 0.7 were right in 41 of 65.
  double surface_hold_correlation = 0.0;
  /// ours (tracking session, 0 = off; needs a learned surface with a colour pattern): while LOST,
  /// a frame whose surface colours correlate below this with the learned ones does not count
  /// towards the recovery (recover_after_good_frames), whatever its keypoints and contour say.
  /// The keypoints hold a static patch of the background as firmly as the object:
  /// hard/can/leave, after the can left the image, 45 of 45 KLT inliers held a blue patch at the
  /// image's border for 35 frames, recovered and tracked, its surface correlating at 0.0-0.04
  /// (the right track: 0.8). Over both hard sets (can, chest), tracked frames with a right pose
  /// correlate below 0.2 in 1-4 %, lost frames with a wrong one in 64-87 %. Frames whose
  /// correlation is not scored (too few surface points shown) are not held back, nor are the
  /// re-acquisition's finds (they passed its own bars). Off in every preset: at 0.3 the dev loop
  /// (both hard sets, 5 initial poses) is -0.04 +- 0.11 AUC paired (leave +0.41, lighting -0.59)
  /// and re-acquisitions come 1-2 frames later; see the README's row.
  double surface_recover_correlation = 0.0;

  // ---- Contour energy refinement (Sec. 3.2-3.5, supplement) ---------------------------------
  bool refine = true;                      ///< false = the `klt_only` baseline
  double sharp_edge_angle_deg = 45.0;      ///< paper: alpha, angle criterion for sharp edges
  int icosphere_subdivisions = 4;          ///< paper: 4 -> 2562 viewpoint directions
  int visibility_resolution_px = 256;      ///< ours: orthographic render size per viewpoint
  std::string visibility_cache_dir;        ///< ours: "" = no disk cache
  double contour_sample_spacing_px = 2.0;  ///< ours: spacing of energy points on the contour
  double blur_sigma_px = 1.1;              ///< paper: Gaussian sigma before the main optimization
  /// ours (coarse_to_fine): weight of the colour frame's chromaticity edges in the contour
  /// energy, beside the grey edges (0 = grey only, the paper). Chromaticity (r - g, r + g - 2 b
  /// over r + g + b) does not change with shading, so the dark rim of a curved object's outline
  /// does not pull the contour inside the object.
  double contour_chroma_weight = 0.0;
  /// ours (needs texture_check_margin): contour_chroma_weight only for a track whose surface,
  /// learned on the initial (colour) frame, has no colour pattern: there the outline is the
  /// only colour edge; a printed pattern's colour edges compete with it.
  bool contour_chroma_plain_only = false;
  int final_hops = 5;                      ///< paper: hops of the last run on the unblurred frame
  double hops_budget = 25000.0;            ///< paper: s = max{1, budget / (|V| + |F|)}
  int min_hops_cap = 100;                  ///< paper: min hops = min{10 s, cap}
  int max_hops_without_improvement_cap = 30;  ///< paper: stop = min{5 s, cap}
  int max_hops_cap = 200;                  ///< paper: max hops = min{30 s, cap}
  double max_reprojection_increase_px = 2.5;  ///< paper: E_max, search area when KLT succeeded
  double extrapolated_rotation_bound_deg = 30.0;   ///< paper: +-Euler angles when extrapolated
  double extrapolated_axial_bound = 0.2;   ///< paper: +- along the camera axis, x object size
  double extrapolated_lateral_bound = 0.1; ///< paper: +- along the other axes, x object size
  double hop_rotation_deg = 2.0;           ///< ours: standard deviation of a hop's rotation
  double hop_translation = 0.01;           ///< ours: std. dev. of a hop's translation, x size
  double metropolis_temperature = 0.05;    ///< ours: Metropolis T, relative to the energy
  int slsqp_max_evaluations = 150;         ///< ours: energy evaluations per local optimization
  std::uint32_t random_seed = 1;           ///< ours: seed of the hop generator (reproducible)

  // ---- Input bounds (ours) -------------------------------------------------------------------
  /// Frames with more pixels are rejected (kInvalidInput) instead of tracked: the work per frame
  /// grows with the pixel count (a 4000x3000 frame took over 8 s with `paper`). Default: 4K UHD
  /// (3840x2160). Each side must also be in [32, 16384] px (core/plausibility.h).
  int max_image_pixels = 3840 * 2160;

  // ---- Coarse-to-fine refinement (ours; the `realtime` preset) ------------------------------
  /// "basin_hopping": the paper's Basin-Hopping + SLSQP on Eq. 5 (Sec. 3.3). "coarse_to_fine":
  /// Levenberg-Marquardt on a weighted sum of cues (pose_cost.h: the contour energy with an
  /// analytic gradient, the keypoint reprojection) over an image pyramid, coarsest first.
  std::string optimizer = "basin_hopping";
  int pyramid_levels = 3;                  ///< ours: coarse_to_fine levels, 1 = full resolution
  /// ours (0 = off): coarse_to_fine starts at the coarsest level where the object (its
  /// diameter at the preliminary pose) is at least this many px across, not coarser. A small
  /// object (40-130 px, 1 m away) shrinks to 10-30 px at a quarter of the resolution, where its
  /// outline is a blur among the clutter's edges and takes the pose away in depth.
  double pyramid_min_object_px = 0.0;
  int iterations_per_level = 4;            ///< ours: coarse_to_fine linearizations per level
  double contour_weight = 1.0;             ///< ours: coarse_to_fine weight of the contour cue
  /// ours: coarse_to_fine weight of the keypoint cue. Weak on purpose: the contour cue must be
  /// able to correct KLT drift (measured on the benchmark: 0.1 beats 1 and 0.03), while the
  /// refined pose is rejected when it leaves the keypoint search area (E_max above).
  double keypoint_weight = 0.1;
  double keypoint_sigma_px = 2.0;          ///< ours: expected keypoint error (cue scale), px
  /// ours (0 = off): when the preliminary pose has no keypoints (KLT failed, or a
  /// re-acquisition hypothesis), the coarse_to_fine refinement first searches image-plane
  /// shifts of it, up to this many object diameters, on the coarsest pyramid level for the
  /// best contour energy, refines from that shift and from the preliminary pose, and keeps the
  /// lower cost. A shift must beat the unshifted energy 1.5 x. A fast move that defeats KLT is
  /// typically 0.2-0.5 diameters (hand-held, 30 Hz), outside the optimizer's basin (a few
  /// coarse px). Hard section (realtime, 24 sequences): 0 -> 10.62 mean AUC, 0.5 -> 10.75,
  /// 0.8 -> 10.86 (sensor effects 5.78 -> 7.86); no change on the OPT-style quick sequences.
  double shift_search_diameters = 0.0;
  /// ours: the shift search scores every second shift of its grid (in both directions), then
  /// the full grid's neighbours of its 8 best (and of staying put), instead of every shift: about a
  /// quarter of the evaluations (the search is a third of a lost frame's time). The energy at
  /// the coarsest level is smooth on the scale of two grid steps.
  bool shift_search_coarse_to_fine = false;
  /// ours (coarse_to_fine only, 0 = off): contour points within this many px (full
  /// resolution) of a KLT anchor whose track failed in the last occlusion_mask_frames frames
  /// (projected at the preliminary pose) are left out of the contour energy. An occluder that
  /// covers part of the object takes its anchors with it; its own outline, next to the hidden
  /// part of the object's, would otherwise pull the contour onto it. Not used on a frame where
  /// more than half of the tracks failed (blur, a jump: nothing tells the occluded part).
  double occlusion_mask_radius_px = 0.0;
  /// ... how many frames a failed anchor stays in the mask (>= 1).
  int occlusion_mask_frames = 5;
  /// ours (0 = no limit): a coarse_to_fine step moves a model point by at most this many px of
  /// its pyramid level (CoarseToFineSettings::max_step_px). Without it a blurred frame with no
  /// keypoints turned the can 145 deg about its own axis in one step (hard/can/occlusion,
  /// frame 1; with 8: 8 deg). Hard + second hard set (48 sequences, realtime): no limit 11.29
  /// mean AUC, 4 px 10.91, 8 px 11.29 (hard 11.20 -> 11.10, second set 11.38 -> 11.47), 16 px
  /// 11.15: a safeguard, not a gain on the benchmark.
  double max_step_px = 0.0;
  /// ours: threads the tracker may use (KLT overlapped with the refinement's image work,
  /// pyramid levels, re-acquisition hypotheses and the colour search in parallel); results do
  /// not depend on it.
  int num_threads = 1;

  /// Throws std::invalid_argument naming the first bad field and its allowed range.
  void validate() const;
};

/// Sets the field called `name` (the member's name above) from its text form; the ROS layer
/// and the tools use it to apply overrides on top of a preset. Throws std::invalid_argument
/// for an unknown name or a value that does not parse (the result is not validated here).
void set_param(TrackerParams& params, const std::string& name, const std::string& value);

/// Every field's name and current value as text, in declaration order (for echoing).
std::vector<std::pair<std::string, std::string>> describe(const TrackerParams& params);

/// Names accepted by make_preset().
std::vector<std::string> preset_names();

/// "realtime" (the default of the nodelet, track_sequence and the benchmark): keypoints as
/// `paper`, refinement by the coarse_to_fine optimizer on two threads (camera rate; see
/// docs/benchmarks.md). "paper": the paper's values (the defaults). "klt_only": keypoints only, no refinement; it
/// re-detects only when the tracks thin out, since re-anchoring every frame on unrefined poses
/// accumulates drift (the strongest keypoint-only baseline, measured in docs/benchmarks.md).
/// Throws std::invalid_argument for an unknown name, listing the known ones.
TrackerParams make_preset(const std::string& name);

}  // namespace kct
