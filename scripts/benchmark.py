#!/usr/bin/env python3
"""Benchmark driver (called by scripts/benchmark.sh, which installs, builds and sources the
workspace first). Three sections:

  hard  hand-held motion (up to 30 mm and 8 deg a frame), clutter with distractors of the
        object's own appearance, untextured and open objects, highlights and cast shadows,
        lighting changes, a moving occluder, leaving the image, motion blur over the shutter
        time, defocus, noise and JPEG (rendered by generate_sequence's scene render).
  real  ViSP's real test sequences from Debian's visp-images-data (cube, castel) scored
        without ground truth (frames held, contour alignment: NOT AUC), and its simulated
        Castle-simu with ground truth (AUC).
  opt   the OPT-style synthetic suite (the paper's Sec. 4 groups and speeds).
  slow  precision on slow footage with the model exact and 3 % off: AUC and median
        rotation / translation errors.
  (and hard2, mismatch, camera, far, long, photo, noise: see SECTIONS and each run_* function)

Generates what is missing under data/benchmark (cached; deterministic from seeds), tracks every
sequence with each configuration (a preset, or a preset with parameter overrides) and writes
one page fragment per section (docs/benchmarks/<section>.md), docs/benchmarks.md (all of
them) and the PNG success curves in docs/benchmarks/. Python standard library only.
"""
import argparse
import csv
import datetime
import json
import math
import os
import platform
import random
import shutil
import shlex
import subprocess
import sys
import time
import zlib

PHOTOS = "/usr/share/doc/opencv-doc/examples/data"
VISP = "/usr/share/visp-images-data/ViSP-images"
SECTIONS = ["hard", "hard2", "mismatch", "camera", "far", "large", "long", "slow", "photo", "noise", "real", "opt"]  # page order: the hard sections first

# ---------------------------------------------------------------------------------------------
# Configurations: a label, a preset and parameter overrides. Add a cue ablation by appending to
# ABLATIONS (it runs only when its preset exists), or on the command line with --variant.
# ---------------------------------------------------------------------------------------------
DEFAULT_PRESETS = ["realtime", "paper", "klt_only"]  # those that exist in the build are run
ABLATIONS = [  # label, preset, --param overrides: the default with and without each of its cues
    # the session's colour model (loss detection + whole-frame search while lost) off
    ("realtime_no_color", "realtime", {"color_search": "false"}),
    # PnP poses far from the expected pose accepted (as paper / klt_only)
    ("realtime_no_motion_bounds", "realtime",
     {"keypoint_max_motion_deg": "0", "keypoint_max_motion_diameters": "0"}),
    # keypoints re-anchored only when the refinement moved them by <= 0.5 px (as paper)
    ("realtime_strict_reanchor", "realtime", {"redetect_max_reprojection_increase_px": "0.5"}),
    # no search of image-plane shifts when KLT fails (the optimizer's basin only)
    ("realtime_no_shift_search", "realtime", {"shift_search_diameters": "0"}),
    # ... that search scoring every shift of its grid (not every second, then around the best)
    ("realtime_every_shift", "realtime", {"shift_search_coarse_to_fine": "false"}),
    # re-acquisition takes only placements above color_accept_ratio (no two-frame confirmation)
    ("realtime_no_confirm", "realtime", {"color_confirm_ratio": "0"}),
    # the colour verdict of a loss taken even while the contour energy or KLT says the pose holds
    ("realtime_no_color_veto", "realtime",
     {"color_contour_veto_ratio": "0", "color_keypoint_veto_inliers": "0"}),
    # no check of turned rotations after a KLT failure or a re-acquisition
    ("realtime_no_rotation_check", "realtime", {"rotation_check_deg": "0"}),
    # no check of turns about the object's own axes against the surface colours learned at start
    ("realtime_no_texture_check", "realtime", {"texture_check_margin": "0"}),
    # ... checked only in rotation_check's window, also for objects with a colour pattern
    ("realtime_texture_check_in_window", "realtime", {"texture_check_every_frame": "false"}),
    # a held pose whose surface colours disagree is not searched for by shifts
    ("realtime_no_texture_shift", "realtime", {"texture_shift_search_below": "0"}),
    # ... nor turned and shifted to where they agree (the local alignment)
    ("realtime_no_texture_align", "realtime", {"texture_align_below": "0"}),
    ("realtime_no_surface_hold", "realtime", {"surface_hold_correlation": "0"}),
    # a KLT failure whose refined pose lost the colours waits for the declared loss to be searched
    ("realtime_no_extrapolated_search", "realtime", {"extrapolated_search_ratio": "0"}),
    # ... and its find taken only above color_accept_ratio (not also when it beats the held pose)
    ("realtime_no_extrapolated_accept", "realtime", {"extrapolated_accept_margin": "0"}),
    ("realtime_no_tracked_search", "realtime", {"tracked_search_ratio": "0"}),
    # ... and its find taken even where the held pose's surface pattern agrees and the find's does not
    ("realtime_no_tracked_surface_check", "realtime", {"tracked_search_surface_drop": "0"}),
    # an object without a colour pattern weighs its keypoints as much as a printed one
    ("realtime_no_plain_surface_scale", "realtime", {"plain_surface_keypoint_scale": "1"}),
    # the contour energy of an object without a colour pattern reads grey edges only
    ("realtime_no_chroma", "realtime", {"contour_chroma_weight": "0"}),
    # the refinement of a small object starts at the pyramid's coarsest level all the same
    ("realtime_no_pyramid_min_object", "realtime", {"pyramid_min_object_px": "0"}),
    # contour points next to anchors whose KLT track just failed (an occluder) are kept
    ("realtime_no_occlusion_mask", "realtime", {"occlusion_mask_radius_px": "0"}),
    # any number of frames in a row that KLT failed on can be good (the contour alone holds a track)
    ("realtime_no_extrapolated_limit", "realtime", {"extrapolated_good_frames": "-1"}),
    # a pose at any depth can be good, and the colour search's depths follow the last good pose's
    ("realtime_no_trusted_depth", "realtime", {"trusted_depth_ratio": "0"}),
    # while lost, a frame recovers on its contour and keypoints alone (a static distractor too)
    ("realtime_no_recovery_check", "realtime", {"color_recover_ratio": "0", "color_recover_min_visible": "0"}),
    # re-acquisition searches the whole frame (not only as far as the object could have moved)
    ("realtime_no_search_reach", "realtime", {"color_search_reach_diameters": "0"}),
    # no second corner detection at a lower quality when few corners pass (untextured objects)
    ("realtime_no_corner_fallback", "realtime", {"corner_fallback_below": "0"}),
    # keypoints anchored after a KLT failure kept even when the frame is judged bad
    ("realtime_keep_anchors", "realtime", {"drop_unconfirmed_anchors": "false"}),
    # while lost, a frame the searches did not re-acquire is refined around the last good pose
    # (not tracked on from where the last frame ended)
    ("realtime_no_track_while_lost", "realtime", {"track_while_lost": "false"}),
    # while lost, a find at the previous frame's find is judged by its quality score alone
    ("realtime_no_repeat_recover", "realtime", {"repeat_recover_diameters": "0"}),
    # ORB keyframes matched while lost (feature_relocalizer.h) off: the colour search alone
    ("realtime_no_feature_relocalization", "realtime", {"feature_relocalization": "false"}),
    # a tracked frame whose surface does not correlate with the learned one is not matched
    # against the keyframes' features
    ("realtime_no_surface_relocalization", "realtime", {"relocalization_below_correlation": "0"}),
    # ... matched around the held pose only, not over the whole frame when nothing is found there
    ("realtime_no_doubt_whole_frame", "realtime", {"relocalization_doubt_whole_frame": "false"}),
    # while lost, the pipeline's pose also goes through rotation_check and texture_check (a
    # lost frame's time, not a cue: the same poses but for a few runs, lost frames slower)
    ("realtime_check_while_lost", "realtime", {"check_while_lost": "true"}),
    # cues that exist but are off by default (measured worse; shown so that it stays visible)
    ("realtime_region", "realtime", {"region_weight": "1"}),
    # the PnP pose made the most likely pose under a prior on the frame-to-frame motion
    ("realtime_keypoint_prior", "realtime", {"keypoint_prior_diameters": "0.1"}),
    # ... matched on every tracked frame as well, replacing a track in doubt they contradict
    ("realtime_relocalization_while_tracking", "realtime", {"relocalization_while_tracking": "true"}),
    ("realtime_motion_model", "realtime",
     {"motion_model": "true", "motion_prior_weight": "1", "keypoint_motion_gate_sigmas": "3"}),
]

# ---------------------------------------------------------------------------------------------
# OPT-style section
# ---------------------------------------------------------------------------------------------
GROUPS_SPEED = ["xy", "z", "inplane", "outofplane"]
GROUPS_SINGLE = ["flash", "movinglight", "free"]
GROUP_TITLES = {"xy": "x-y translation", "z": "z translation", "inplane": "in-plane rotation",
                "outofplane": "out-of-plane rotation", "flash": "flash light",
                "movinglight": "moving light", "free": "free motion"}
BACKGROUNDS = ["home.jpg", "aero3.jpg", "leuvenB.jpg", "graf3.png", "basketball1.png",
               "box_in_scene.png", "rubberwhale1.png", "licenseplate_motion.jpg"]
# Benchmark objects: model name, resolution, focal length (px; same field of view at both
# resolutions), frames generated and tracked in the full run.
OBJECTS = {
    "can": dict(model="can", width=640, height=480, fx=525.0, frames=60),
    "chest": dict(model="chest", width=640, height=480, fx=525.0, frames=60),
    "rock": dict(model="rock", width=640, height=480, fx=525.0, frames=60),
    # ~3 s/frame with the paper preset on 2 cores: a short sequence keeps the full run < 1 h.
    "bike": dict(model="bike", width=640, height=480, fx=525.0, frames=12),
    "can_1080p": dict(model="can", width=1920, height=1080, fx=1575.0, frames=40),
}
QUICK_OBJECTS = ["can", "chest"]
QUICK_SEQUENCES = [(g, s) for g in GROUPS_SPEED for s in (1, 5)] + [(g, 3) for g in GROUPS_SINGLE]
QUICK_FRAMES = int(os.environ.get("KCT_BENCH_QUICK_FRAMES", "30"))  # override only for smoke tests
MOTION_BLUR_SAMPLES = 4
NOISE_SIGMA = 2.0

# ---------------------------------------------------------------------------------------------
# Hard section
# ---------------------------------------------------------------------------------------------
HARD_FRAMES = 80
HARD_OBJECTS = {
    # model, whether it is textured, extra render options
    "can": dict(model="can", kind="textured", render=["--smooth-shading"]),
    "chest": dict(model="chest", kind="textured", render=[]),
    "toy": dict(model="toy", kind="untextured", render=["--smooth-shading"]),
    "castle": dict(model="castle", kind="untextured, open mesh", render=[]),
}
# Every hard sequence: hand-held motion, highlights, cast shadows, 1/60 s shutter at 30 fps,
# noise and JPEG; each condition adds its difficulty.
HARD_BASE = ["--trajectory", "handheld", "--typical-translation-mm", "5", "--typical-rotation-deg", "1.5",
             "--jerk-probability", "0.05", "--specular", "0.4", "--shininess", "40", "--shadows",
             "--shutter-fraction", "0.5", "--motion-blur-samples", "6", "--noise-sigma", "3",
             "--jpeg-quality", "85"]
HARD_CONDITIONS = {
    "handheld": ("hand-held", []),
    "clutter": ("clutter + own-colour distractors", ["--distractors", "3"]),
    "occlusion": ("moving occluder", ["--occluder-passes", "2"]),
    "leave": ("leaves and re-enters", ["--leave-start", "25", "--leave-frames", "14"]),
    "lighting": ("lighting changes", ["--lighting-changes"]),
    "sensor": ("blur, defocus, noise, JPEG", ["--shutter-fraction", "1.0", "--defocus-px", "2",
                                              "--noise-sigma", "7", "--jpeg-quality", "35"]),
}
HARD_BACKGROUNDS = {"clutter": ["box_in_scene.png", "stuff.jpg", "fruits.jpg", "pic3.png"]}
HARD_QUICK = dict(objects=["can", "toy"], conditions=["handheld", "clutter", "occlusion"], frames=40)
HARD_MIN_VISIBLE = 0.1  # frames where less of the object is seen are not scored
# The hard sections track every preset on every frame (paper: ~5 min of CPU a section at 640x480),
# so that the presets compare on the same frames; their first HARD_FIRST_FRAMES frames (before most
# losses) get a table of their own. The noise section, 10 x the tracking, gives slow presets the
# first N frames only.
HARD_FIRST_FRAMES = 40
NOISE_TRACK_FRAMES = {"paper": 40}

# ---------------------------------------------------------------------------------------------
# Real section: ViSP's sequences (Debian visp-images-data)
# ---------------------------------------------------------------------------------------------
REAL = {
    "cube": dict(title="mbt/cube: real, 218 frames, cube held in hand",
                 images=VISP + "/mbt/cube", prefix="image", xml=VISP + "/mbt/cube.xml",
                 pose=VISP + "/mbt/cube.0.pos", model=VISP + "/mbt/cube.cao"),
    "castel": dict(title="mbt-depth/castel: real, 30 frames, open low-poly castle",
                   images=VISP + "/mbt-depth/castel/castel", prefix="image_",
                   xml=VISP + "/mbt-depth/castel/chateau.xml",
                   pose=VISP + "/mbt-depth/castel/chateau.0.pos",
                   model=VISP + "/mbt-depth/castel/chateau.cao"),
    "castle_simu": dict(title="mbt-depth/Castle-simu: simulated, 40 frames, ground truth",
                        images=VISP + "/mbt-depth/Castle-simu/Images", prefix="Image_",
                        xml=VISP + "/mbt-depth/Castle-simu/Config/chateau.xml",
                        poses=VISP + "/mbt-depth/Castle-simu/CameraPose",
                        model=VISP + "/mbt-depth/Castle-simu/Models/chateau.cao"),
}
REAL_QUICK = ["castel", "castle_simu"]


def log(msg):
    print("[%s] %s" % (time.strftime("%H:%M:%S"), msg), file=sys.stderr, flush=True)


def rosrun(tool, *args, **kw):
    return subprocess.run(["rosrun", "klt_contour_tracker", tool] + [str(a) for a in args], **kw)


def cached_run(cmd, folder, what):
    """Runs cmd unless folder/generated_by.txt records the same command (then the data is
    cached)."""
    stamp = os.path.join(folder, "generated_by.txt")
    wanted = " ".join(shlex.quote(str(c)) for c in cmd) + "\n"
    if os.path.exists(stamp) and open(stamp).read() == wanted:
        return folder
    log("data: %s" % what)
    subprocess.run([str(c) for c in cmd], check=True, stdout=subprocess.DEVNULL)
    with open(stamp, "w") as f:
        f.write(wanted)
    return folder


def ensure_model(data, model):
    path = os.path.join(data, "models", model + ".obj")
    if not os.path.exists(path):
        log("models: generating %s" % model)
        rosrun("make_benchmark_models", "--output-dir", os.path.join(data, "models"), "--only", model,
               check=True)
    return path


def auc(errors, diameter):
    """The paper's AUC (Sec. 4.1), as kct::auc_score: k in [0, 0.2] of the diameter, of 20."""
    if not errors:
        return None
    return 100.0 * sum(max(0.0, 0.2 - e / diameter) for e in errors) / len(errors)


def first_frames_auc(rows, n):
    """AUC over the first n frames of each row's sequence (its visible_errors: metres, None where
    not scored), each error normalized by its row's diameter: presets tracked on different
    numbers of frames, compared on the frames they share."""
    return auc([e / r["diameter_m"] for r in rows for e in r["visible_errors"][:n] if e is not None], 1.0)


def read_visible(folder):
    """`folder`'s visible.txt: per frame, the fraction of the object's silhouette in the image
    and not occluded (comment lines skipped)."""
    return [float(l) for l in open(os.path.join(folder, "visible.txt")) if not l.startswith("#")]


def score_visible(row, source):
    """Scores a tracked hard-style run `row` (Runner.track's summary) on the frames where at least
    HARD_MIN_VISIBLE of the object is seen (`source`'s visible.txt): sets its auc, scored_frames
    and visible_errors (metres, None where not scored); returns the visible fractions."""
    visible = read_visible(source)
    scored = [e for e, v in zip(row["errors"], visible) if v >= HARD_MIN_VISIBLE]
    row.update(auc=auc(scored, row["diameter_m"]), scored_frames=len(scored),
               visible_errors=[(e if v >= HARD_MIN_VISIBLE else None) for e, v in zip(row["errors"], visible)])
    return visible


def weighted_auc(rows):
    """AUC over all scored frames of `rows` (the AUC is a per-frame mean, so this is exact)."""
    n = sum(r["scored_frames"] for r in rows if r.get("auc") is not None)
    return sum(r["auc"] * r["scored_frames"] for r in rows if r.get("auc") is not None) / n if n else None


def median(values):
    v = sorted(x for x in values if x is not None)
    if not v:
        return None
    m = len(v) // 2
    return v[m] if len(v) % 2 else 0.5 * (v[m - 1] + v[m])


def fmt(x, digits=2):
    return "-" if x is None else "%.*f" % (digits, x)


def plot(path, title, curves, tmp):
    """curves: [(label, normalized errors)] -> PNG via plot_success_curves."""
    cmd = ["rosrun", "klt_contour_tracker", "plot_success_curves", "--output", path, "--title", title]
    for i, (label, errors) in enumerate(curves):
        if not errors:
            continue
        f = os.path.join(tmp, "curve_%d.txt" % i)
        with open(f, "w") as out:
            out.write("\n".join("%.9g" % e for e in errors) + "\n")
        cmd += ["--curve", label, f]
    subprocess.run(cmd, check=True)


def machine():
    cpu = "unknown"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return "%s, %d logical cores (nproc), %s" % (cpu, os.cpu_count(), platform.platform())


def code_version(repo):
    """KCT_BENCH_CODE when set (e.g. a snapshot built elsewhere), else the repo's HEAD."""
    if os.environ.get("KCT_BENCH_CODE"):
        return os.environ["KCT_BENCH_CODE"]
    try:
        commit = subprocess.run(["git", "-C", repo, "rev-parse", "--short", "HEAD"],
                                capture_output=True, text=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", repo, "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True).stdout.strip()
    except OSError:
        return "unknown"
    return "commit %s%s" % (commit, " (with uncommitted changes)" if dirty else "")


def available_presets():
    """The presets track_sequence knows (its usage lists them)."""
    proc = rosrun("track_sequence", "--help", capture_output=True, text=True)
    for line in (proc.stdout + proc.stderr).splitlines():
        if line.strip().startswith("presets:"):
            return line.split(":", 1)[1].split()
    return ["paper", "klt_only"]


def sequence_frames(folder, max_frames=None):
    """Frames the tools track in the sequence `folder`: its images, as sequence_io reads them
    (png, jpg, jpeg, bmp), at most max_frames."""
    n = len([f for f in os.listdir(folder)
             if os.path.splitext(f)[1].lower() in (".png", ".jpg", ".jpeg", ".bmp")])
    return min(n, max_frames) if max_frames else n


class Runner:
    """Tracks a sequence with a configuration and returns the summary JSON (plus the per-frame
    errors), or None when track_sequence failed."""

    def __init__(self, repo, results, reuse=(), track_sequence=("rosrun", "klt_contour_tracker", "track_sequence")):
        """track_sequence: the command that runs it (the built package's, or any binary)."""
        self.repo, self.results, self.reuse = repo, results, set(reuse)
        self.track_sequence = list(track_sequence)

    def reusable(self, json_path, folder, max_frames, label, name):
        """A reused result counts only when it tracked the frames this run would: a result from
        an earlier frame cap (e.g. `paper` on 40 frames before 040f88b) is tracked again."""
        with open(json_path) as f:
            frames = json.load(f).get("frames")
        want = sequence_frames(folder, max_frames)
        if frames == want:
            return True
        log("--reuse %s %s: the stored result tracked %s frames, this run tracks %d: tracking again"
            % (label, name, frames, want))
        return False

    def track(self, section, config, name, folder, model, max_frames=None, model_scale=None, score_model=None,
              hypotheses=False):
        """hypotheses: also write the colour searches' refined hypotheses (track_sequence
        --hypotheses) to the summary's "hypotheses_file" (dev_loop.py reach)."""
        label, preset, params = config
        out = os.path.join(self.results, section, label)
        os.makedirs(out, exist_ok=True)
        base = os.path.join(out, name.replace("/", "_"))
        cmd = self.track_sequence + ["--sequence", folder, "--model", model,
               "--preset", preset,
               "--param", "visibility_cache_dir=" + os.path.join(self.repo, "data", "cache", "visibility"),
               "--output", base + ".poses.txt", "--summary-json", base + ".json",
               "--trace", base + ".trace.csv", "--quiet"]
        with open(os.path.join(folder, "pose.txt")) as f:
            if len([l for l in f if l.strip() and not l.startswith("#")]) > 1:  # ground truth
                cmd += ["--errors", base + ".errors.txt"]
        if model_scale:
            cmd += ["--model-scale", str(model_scale)]
        if score_model:  # the tracker's model is off the object: scored against the true shape
            cmd += ["--score-model", score_model]
        for k, v in sorted(params.items()):
            cmd += ["--param", "%s=%s" % (k, v)]
        if max_frames:
            cmd += ["--max-frames", str(max_frames)]
        if hypotheses:
            cmd += ["--hypotheses", base + ".hypotheses.csv"]
        t0 = time.time()
        if label in self.reuse and os.path.exists(base + ".json") and \
                self.reusable(base + ".json", folder, max_frames, label, name):
            pass  # --reuse: the previous run's result of this configuration
        else:
            for f in (base + ".json", base + ".errors.txt", base + ".trace.csv", base + ".hypotheses.csv"):
                if os.path.exists(f):
                    os.remove(f)
            proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            if proc.returncode != 0:
                log("FAILED %s %s: %s" % (label, name, proc.stderr.strip()[-300:]))
                return None
            with open(os.path.join(out, "CODE"), "w") as f:  # for a later --reuse
                f.write("%s, %s\n" % (os.environ.get("KCT_BENCH_CODE", "?"),
                                      datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")))
        with open(base + ".json") as f:
            summary = json.load(f)
        if hypotheses:
            summary["hypotheses_file"] = base + ".hypotheses.csv"
        summary["errors"] = []
        if os.path.exists(base + ".errors.txt"):
            with open(base + ".errors.txt") as f:
                summary["errors"] = [float(x) for x in f.read().split()]
        # The session's per-frame verdict (the trace's `good`: what ~status tells a ROS user),
        # absent from results made before the trace was written.
        summary["good"] = summary["states"] = None
        if os.path.exists(base + ".trace.csv"):
            with open(base + ".trace.csv") as f:
                trace = list(csv.DictReader(f))
            # One verdict per frame: a frame dropped at --camera-rate has no trace line and keeps
            # the last tracked frame's verdict, as it keeps its pose.
            by_frame = {int(row["frame"]): row for row in trace}
            frames = max(summary.get("frames", 0), max(by_frame, default=-1) + 1)
            rows, last_row = [], None
            for i in range(frames):
                last_row = by_frame.get(i, last_row)
                if last_row is not None:
                    rows.append(last_row)
            summary["good"] = [row["good"] == "1" for row in rows]
            summary["states"] = [row["state"] for row in rows]
        summary.update(preset=label, wall_s=time.time() - t0, poses_file=base + ".poses.txt")
        return summary


def header_lines(title, args, start, duration_s, gen_s, load_start, load_end, extra=()):
    L = ["## %s\n" % title]
    L.append("- **Command:** `%s`" % args.command)
    L.append("- **Date:** %s" % start.strftime("%Y-%m-%d %H:%M UTC"))
    L.append("- **Machine:** %s" % machine())
    L.append("- **Code:** %s" % code_version(args.repo))
    L.append("- **Duration of this section:** %.1f min (of which %.1f min generating missing data)" % (
        duration_s / 60, gen_s / 60))
    busy = max(load_start, load_end) > 0.5 * (os.cpu_count() or 1) + 0.5
    L.append("- **Load average** (1 min) at start / end: %.2f / %.2f on %d cores.%s" % (
        load_start, load_end, os.cpu_count(),
        " The CPU was shared with other jobs: frame times are noisy and pessimistic." if busy else ""))
    if args.reuse:
        # The results folder of the section: its key in SECTION_TITLES (hard2, camera, large...),
        # else the title's first word (noise, real, slow, OPT-style).
        section = {v: k for k, v in SECTION_TITLES.items()}.get(title) or \
            title.split()[0].lower().replace("opt-style", "opt")
        origins = []
        for label in args.reuse:
            code = os.path.join(args.data_results, section, label, "CODE")
            if section == "noise":
                code = os.path.join(args.data_results, section, label + "_draw0", "CODE")
            origins.append("%s (%s)" % (label, open(code).read().strip() if os.path.exists(code) else "?"))
        L.append("- **Reused results** (`--reuse`: tracked by an earlier run; its code and date): %s"
                 % "; ".join(origins))
    L.extend(extra)
    L.append("")
    return L


def speed_table(rows, configs, key_rows):
    """Median of the per-sequence median frame times (first frame excluded), ms."""
    L = ["| object | faces | resolution | " + " | ".join(c[0] for c in configs) + " |",
         "|---|---|---|" + "---|" * len(configs)]
    for name, rr in key_rows:
        if not rr:
            continue
        L.append("| %s | %d | %dx%d | %s |" % (name, rr[0]["faces"], rr[0]["width"], rr[0]["height"], " | ".join(
            fmt(median([r["median_ms"] for r in rr if r["preset"] == c[0]]), 1) for c in configs)))
    return L


def tail_table(rows, configs, key_rows):
    """The slow frames: per object, the median over its sequences of each sequence's 90th
    percentile frame time, and the slowest frame of any of its sequences, ms. Only configurations
    whose results carry them (results from before p90_ms/max_ms was written show none)."""
    tailed = [c[0] for c in configs if any("p90_ms" in r for r in rows if r["preset"] == c[0])]
    if not tailed:
        return []
    L = ["Slow frames: median over the sequences of each sequence's 90th-percentile `track()` time, "
         "and in brackets the slowest frame of all the object's sequences, ms (a frame above the camera "
         "period is a frame the nodelet's queue has to absorb).\n",
         "| object | " + " | ".join(tailed) + " |", "|---|" + "---|" * len(tailed)]
    for name, rr in key_rows:
        if not rr:
            continue
        cells = []
        for p in tailed:
            mine = [r for r in rr if r["preset"] == p and "p90_ms" in r]
            cells.append("%s (%s)" % (fmt(median([r["p90_ms"] for r in mine]), 1),
                                      fmt(max([r["max_ms"] for r in mine]) if mine else None, 0)))
        L.append("| %s | %s |" % (name, " | ".join(cells)))
    L.append("")
    return L


STAGES = [("klt", "KLT"), ("pnp", "PnP"), ("keypoint_detection", "keypoint detection"),
          ("image", "image (pyramid, gradients)"), ("contour_extraction", "contour extraction"),
          ("energy", "energy (cues)"), ("optimizer", "optimizer")]


def stage_table(rows, configs, key_rows):
    """Where the time goes (speed's table): median over the sequences of each stage's median, ms."""
    staged = [c[0] for c in configs if any("stage_median_ms" in r for r in rows if r["preset"] == c[0])]
    if not staged:
        return []
    L = ["Where the time goes: median over the sequences of each stage's median time per frame, ms. With "
         "2 threads the refinement's image work runs while KLT does, so the stages may add up to more "
         "than the frame time.\n",
         "| preset | object | frame | " + " | ".join(t for _, t in STAGES) + " |",
         "|---|---|---|" + "---|" * len(STAGES)]
    for p in staged:
        for name, rr in key_rows:
            rr = [r for r in rr if r["preset"] == p and "stage_median_ms" in r]
            if rr:
                L.append("| %s | %s | %s | %s |" % (p, name, fmt(median([r["median_ms"] for r in rr]), 1), " | ".join(
                    fmt(median([r["stage_median_ms"].get(k, 0.0) for r in rr]), 1) for k, _ in STAGES)))
    return L + [""]


# Issue 11: a loss counts as re-acquired in time when the session tracks again within this
# many frames.
REACQUIRE_WITHIN_FRAMES = 10
SESSION_COLUMNS = ["losses", "re-acquired", "within %d frames" % REACQUIRE_WITHIN_FRAMES,
                   "within %d frames, right" % REACQUIRE_WITHIN_FRAMES,
                   "within %d frames of being visible, right" % REACQUIRE_WITHIN_FRAMES,
                   "median frames to re-acquire", "frames lost"]


def session_counts(rows):
    """The loss table's columns when track_sequence reported the tracking session's losses."""
    return SESSION_COLUMNS if any("losses" in r for r in rows) else []


def count_share(count, whole):
    """`count` and its share of `whole` as "n (p %)"; just n when `whole` is 0."""
    return "%d (%d %%)" % (count, round(100.0 * count / whole)) if whole else str(count)


# A pose whose error is at least this share of the object's diameter is wrong (AUC counts it at
# most half; ADD-0.1d, the common pass mark, fails it).
WRONG_POSE_DIAMETERS = 0.1
VERDICT_COLUMNS = ["scored frames", "reported good", "good but wrong", "AUC lost on them",
                   "reported bad", "bad but right"]


def verdict_cells(rows):
    """How far the session's per-frame verdict (good / bad) can be trusted, over the scored frames
    of `rows` (each with `good_scored`: (good, normalized error) pairs): frames reported good,
    those of them whose pose is wrong (error >= WRONG_POSE_DIAMETERS diameters) and the AUC
    points they cost the whole set, frames reported bad and those of them that were right.
    None when a row has no trace."""
    if any(r.get("good_scored") is None for r in rows):
        return None
    pairs = [p for r in rows for p in r["good_scored"]]
    if not pairs:
        return None
    good = [e for g, e in pairs if g]
    bad = [e for g, e in pairs if not g]
    wrong = [e for e in good if e >= WRONG_POSE_DIAMETERS]
    right_bad = [e for e in bad if e < WRONG_POSE_DIAMETERS]
    # What the wrong frames cost the AUC of all frames: their shortfall from 20, weighted by
    # their share of the frames.
    lost = (20.0 - auc(wrong, 1.0)) * len(wrong) / len(pairs) if wrong else 0.0
    return [str(len(pairs)), count_share(len(good), len(pairs)), count_share(len(wrong), len(good)),
            "%.2f" % lost, count_share(len(bad), len(pairs)), count_share(len(right_bad), len(bad))]


def reacquired_right_in_time(row):
    """Re-acquisitions of `row` (from its trace's states) within REACQUIRE_WITHIN_FRAMES of the
    loss whose pose at the re-acquisition frame is right (error < WRONG_POSE_DIAMETERS
    diameters); None without a trace."""
    states, errors = row.get("states"), row.get("errors", [])
    if states is None or len(states) != len(errors):
        return None
    right, lost_at = 0, None
    for i in range(1, len(states)):
        if states[i - 1] == "tracking" and states[i] == "lost":
            lost_at = i
        elif states[i - 1] == "lost" and states[i] == "tracking" and lost_at is not None:
            if i - lost_at <= REACQUIRE_WITHIN_FRAMES and errors[i] < WRONG_POSE_DIAMETERS * row["diameter_m"]:
                right += 1
            lost_at = None
    return right


def reacquired_right_once_visible(row):
    """Issue 11's measure: (right, losses) where losses are the losses after which the object is
    visible again (at least HARD_MIN_VISIBLE of it, `visible_errors` not None) before the sequence
    ends, and right are those of them re-acquired within REACQUIRE_WITHIN_FRAMES of the frame it
    is visible from (the first such frame at or after the loss; when the object is out of sight
    for a while after the loss, before the re-acquisition, the frame it is back from) with a right
    pose (error < WRONG_POSE_DIAMETERS diameters). A re-acquisition before the object is back (on
    the background) is not right. None without a trace or visibility."""
    states, errors, visible = row.get("states"), row.get("errors", []), row.get("visible_errors")
    if states is None or visible is None or not (len(states) == len(errors) == len(visible)):
        return None
    right = losses = 0
    i = 1
    while i < len(states):
        if not (states[i - 1] == "tracking" and states[i] == "lost"):
            i += 1
            continue
        end = next((k for k in range(i + 1, len(states)) if states[k] == "tracking"), None)
        # The object left the image (or the occluder hid it) after the loss: the clock starts
        # when it is back, not at the loss, while it was still partly in view.
        hidden = [k for k in range(i, len(states) if end is None else end) if visible[k] is None]
        start = hidden[-1] + 1 if hidden else i
        back = next((k for k in range(start, len(states)) if visible[k] is not None), None)
        if back is not None:
            losses += 1
            if (end is not None and back <= end <= back + REACQUIRE_WITHIN_FRAMES and
                    errors[end] < WRONG_POSE_DIAMETERS * row["diameter_m"]):
                right += 1
        if end is None:
            break
        i = end + 1
    return right, losses


def session_cells(rows):
    """Losses, re-acquisitions (all; within REACQUIRE_WITHIN_FRAMES, share of the losses; of
    those, the ones whose pose is right), the median number of frames from a loss to its
    re-acquisition and the frames spent lost, summed over `rows`."""
    frames = [int(f) for r in rows for f in r.get("frames_to_reacquire", [])]
    within = sum(1 for f in frames if f <= REACQUIRE_WITHIN_FRAMES)
    losses = sum(int(r.get("losses", 0)) for r in rows)
    right = [reacquired_right_in_time(r) for r in rows]
    once_visible = [reacquired_right_once_visible(r) for r in rows]
    middle = median(frames)
    return [str(losses), str(sum(int(r.get("reacquisitions", 0)) for r in rows)),
            count_share(within, losses),
            count_share(sum(right), losses) if None not in right else "-",
            count_share(sum(v[0] for v in once_visible), sum(v[1] for v in once_visible))
            if None not in once_visible else "-",
            "%g" % middle if middle is not None else "-", str(sum(int(r.get("frames_lost", 0)) for r in rows))]


# ---------------------------------------------------------------------------------------------
# Hard section
# ---------------------------------------------------------------------------------------------
# The hard sets: the same objects and conditions rendered with other seeds (trajectories, jerks,
# occluder, distractors) and backgrounds. One set moves by up to +-4 AUC per sequence on tiny
# numerical changes; a change is judged on both (48 sequences). name: (seed tag, background index
# from the seed, title).
HARD_SETS = {
    "hard": ("hard", lambda seed: seed, "Hard section"),
    "hard2": ("dev2", lambda seed: seed // 7, "Hard section, second seed set"),
}


SECTION_TITLES = dict({k: v[2] for k, v in HARD_SETS.items()}, photo="Photo section (path-traced)",
                      mismatch="Mismatch section (the model 3 % off the object)",
                      camera="Camera-rate section (the hard set as a live 30 Hz camera)",
                      far="Far section (small in the image: 0.9-1.3 m away)",
                      large="Large-mesh section (a 150k-face model in the hard rendering)",
                      long="Long section (300 frames a sequence: what a wrong hold costs)")


def sequence_seed(tag, obj, cond):
    """The seed of a generated sequence, from its set's tag, object and condition."""
    return zlib.crc32(("%s/%s/%s" % (tag, obj, cond)).encode()) % 100000 + 1


def object_spec(obj):
    """The hard sections' object `obj` (HARD_OBJECTS, or the large-mesh section's LARGE_OBJECTS)."""
    return HARD_OBJECTS[obj] if obj in HARD_OBJECTS else LARGE_OBJECTS[obj]


def generated_sequence(data, obj, folder, frames, seed, background, options, extra, what):
    """generate_sequence of a hard object into folder, cached: `options`, then the object's
    render options, then `extra`."""
    spec = object_spec(obj)
    cmd = ["rosrun", "klt_contour_tracker", "generate_sequence", "--model", ensure_model(data, spec["model"]),
           "--output-dir", folder, "--frames", frames, "--seed", seed,
           "--background", os.path.join(PHOTOS, background)] + list(options) + spec["render"] + list(extra)
    return cached_run(cmd, folder, what)


def hard_sequence(data, obj, cond, frames, set_name="hard"):
    tag, background_index, _ = HARD_SETS[set_name]
    seed = sequence_seed(tag, obj, cond)
    backgrounds = HARD_BACKGROUNDS.get(cond, BACKGROUNDS)
    return generated_sequence(data, obj, os.path.join(data, set_name, obj, cond), frames, seed,
                              backgrounds[background_index(seed) % len(backgrounds)], HARD_BASE,
                              HARD_CONDITIONS[cond][1], "rendering %s/%s/%s" % (set_name, obj, cond))


# ---------------------------------------------------------------------------------------------
# Mismatch section: the hard section's frames tracked with a model that is off the object
# ---------------------------------------------------------------------------------------------
# On real video the model is never the object: a CAD model or a scan has shape and scale errors,
# real edges are rounded. The renders are made with the very mesh the tracker is given, so there
# the contour energy's optimum is the true pose; here the tracker gets the mesh stretched by
# MISMATCH_SCALE along its own x, y, z axes about its bounding box centre (a 3 % shape error) and
# is scored against the true shape (track_sequence --score-model), so a cue that trusts a biased
# contour over the keypoints loses here.
MISMATCH_SCALE = (1.03, 0.97, 1.0)
MISMATCH_SET = "hard"  # whose frames are tracked


def mismatched_model(data, model):
    """data/models_mismatch/<model>.obj: the benchmark model's vertices scaled by MISMATCH_SCALE
    about its bounding box centre (normals, texture coordinates, faces and materials as they are;
    the material and texture files are links to the model's). Written once (cached)."""
    source = ensure_model(data, model)
    folder = os.path.join(data, "models_mismatch")
    path = os.path.join(folder, model + ".obj")
    stamp = path + ".scale"
    wanted = " ".join("%g" % f for f in MISMATCH_SCALE) + "\n"
    if os.path.exists(path) and os.path.exists(stamp) and open(stamp).read() == wanted:
        return path
    os.makedirs(folder, exist_ok=True)
    for name in os.listdir(os.path.dirname(source)):  # materials and textures, by the OBJ's relative names
        link = os.path.join(folder, name)
        if not name.endswith(".obj") and not os.path.lexists(link):
            os.symlink(os.path.join(os.path.dirname(source), name), link)
    lines = open(source).read().splitlines()
    vertices = [[float(x) for x in l.split()[1:4]] for l in lines if l.startswith("v ")]
    centre = [(min(v[i] for v in vertices) + max(v[i] for v in vertices)) / 2 for i in range(3)]
    out = []
    for l in lines:
        if l.startswith("v "):
            f = l.split()
            xyz = [centre[i] + MISMATCH_SCALE[i] * (float(f[1 + i]) - centre[i]) for i in range(3)]
            l = "v " + " ".join("%.9g" % x for x in xyz + [float(x) for x in f[4:]])
        out.append(l)
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")
    with open(stamp, "w") as f:
        f.write(wanted)
    return path


def run_mismatch(args, configs, runner, data, docs_dir, tmp):
    objects = HARD_QUICK["objects"] if args.quick else list(HARD_OBJECTS)
    conditions = HARD_QUICK["conditions"] if args.quick else list(HARD_CONDITIONS)
    frames = HARD_QUICK["frames"] if args.quick else (args.hard_frames or HARD_FRAMES)
    # Rendered inside run_hard, so that its header counts the rendering time.
    folders = lambda: {(o, c): hard_sequence(data, o, c, frames, MISMATCH_SET) for o in objects for c in conditions}
    models = {o: (mismatched_model(data, HARD_OBJECTS[o]["model"]),
                  os.path.join(data, "models", HARD_OBJECTS[o]["model"] + ".obj")) for o in objects}
    return run_hard(args, configs, runner, data, docs_dir, tmp, set_name="mismatch", folders=folders,
                    models=models, folder_frames=frames)


# ---------------------------------------------------------------------------------------------
# Camera-rate section: the hard set replayed as a live camera
# ---------------------------------------------------------------------------------------------
CAMERA_RATE_HZ = 30.0


def run_camera(args, configs, runner, data, docs_dir, tmp):
    """The hard set's sequences, each default preset tracked on every frame and as a live 30 Hz
    camera (track_sequence --camera-rate: a frame a newer one replaced while the tracker was busy
    is dropped and holds the last pose, as the nodelet's one-message queue does). What a ROS user
    gets is the second; the other sections score the first. Timing-dependent: this machine, its
    load."""
    configs = [c for c in configs if c[0] in DEFAULT_PRESETS]
    frames = HARD_QUICK["frames"] if args.quick else (args.hard_frames or HARD_FRAMES)
    objects = HARD_QUICK["objects"] if args.quick else list(HARD_OBJECTS)
    conditions = HARD_QUICK["conditions"] if args.quick else list(HARD_CONDITIONS)
    start = datetime.datetime.now(datetime.timezone.utc)
    load_start, t0 = os.getloadavg()[0], time.time()
    folders = {(o, c): hard_sequence(data, o, c, frames, "hard") for o in objects for c in conditions}
    gen_s = time.time() - t0
    live_runner = Runner(runner.repo, runner.results, runner.reuse,
                         runner.track_sequence + ["--camera-rate", "%g" % CAMERA_RATE_HZ])
    rows = []
    for config in configs:
        # mode, its runner, the results folder its runs go to
        for mode, r_runner, section in (("every frame", runner, "camera"),
                                        ("30 Hz", live_runner, "camera_live")):
            for (o, c), folder in folders.items():
                model = os.path.join(data, "models", HARD_OBJECTS[o]["model"] + ".obj")
                r = r_runner.track(section, config, "%s/%s" % (o, c), folder, model)
                if not r:
                    continue
                score_visible(r, folder)
                r.update(object=o, condition=c, mode=mode)
                log("camera %-10s %-11s %-7s %-10s AUC %5.2f  dropped %3d  median %6.1f ms" % (
                    config[0], mode, o, c, r["auc"] or 0, r.get("dropped_frames", 0), r["median_ms"]))
                rows.append(r)
    duration = time.time() - t0
    load_end = os.getloadavg()[0]

    def sel(**kw):
        return [r for r in rows if all(r[k] == v for k, v in kw.items())]
    L = header_lines(SECTION_TITLES["camera"], args, start, duration, gen_s, load_start, load_end, [
        "- **Mode:** %s (the hard set: %d objects x %d conditions x %d frames; %s)" % (
            "quick" if args.quick else "full", len(objects), len(conditions), frames,
            ", ".join(c[0] for c in configs))])
    L.append("The `hard` set's sequences (the hard section's frames), each preset tracked twice: on "
             "every frame, as the other sections do (a bag played paced on the tracker), and as a live "
             "%g Hz camera (`track_sequence --camera-rate %g`): frame i arrives at i / %g s, the tracker "
             "takes each frame as long as its `track()` took here, and a frame that a newer one replaced "
             "while it was busy is dropped, as the nodelet's default one-message queue (`~queue_size` 1) "
             "drops it; a dropped frame is scored with the last pose (what the robot holds then). The "
             "live score is what a ROS user on this machine gets; it depends on the machine and its "
             "load (above).\n" % (CAMERA_RATE_HZ, CAMERA_RATE_HZ, CAMERA_RATE_HZ))
    L.append("### AUC per condition, every frame and live\n")
    L.append("| preset | tracked | " + " | ".join(conditions) + " | **all** |")
    L.append("|---|---|" + "---|" * (len(conditions) + 1))
    for c in configs:
        for mode in ("every frame", "30 Hz"):
            L.append("| %s | %s | %s | **%s** |" % (
                c[0], mode, " | ".join(fmt(weighted_auc(sel(preset=c[0], mode=mode, condition=k)))
                                       for k in conditions),
                fmt(weighted_auc(sel(preset=c[0], mode=mode)))))
    L.append("")
    L.append("### Frames dropped live\n")
    L.append("Share of the frames a %g Hz stream dropped (never tracked), per condition, and the "
             "every-frame run's median and 90th-percentile `track()` time (median over the "
             "sequences), ms.\n" % CAMERA_RATE_HZ)
    L.append("| preset | " + " | ".join(conditions) + " | **all** | median ms | p90 ms |")
    L.append("|---|" + "---|" * (len(conditions) + 3))

    def dropped(rr):
        total = sum(r.get("frames", 0) for r in rr)
        return "%.0f %%" % (100.0 * sum(r.get("dropped_frames", 0) for r in rr) / total) if total else "-"
    for c in configs:
        every = sel(preset=c[0], mode="every frame")
        L.append("| %s | %s | **%s** | %s | %s |" % (
            c[0], " | ".join(dropped(sel(preset=c[0], mode="30 Hz", condition=k)) for k in conditions),
            dropped(sel(preset=c[0], mode="30 Hz")),
            fmt(median([r["median_ms"] for r in every]), 1) if every else "-",
            fmt(median([r["p90_ms"] for r in every if "p90_ms" in r]), 1) if every else "-"))
    L.append("")
    return L, rows


# ---------------------------------------------------------------------------------------------
# Photo section: the hard section's trajectories path-traced by Blender's Cycles
# ---------------------------------------------------------------------------------------------
# scripts/photoreal_render.py re-renders a hard sequence's trajectory (its pose.txt, K.txt and
# visible.txt are the ground truth): soft shadows, inter-reflections, true motion blur, depth of
# field, sampling noise, a camera's tone curve, clutter in the object's own texture or colour.
# condition: description, source (hard set, condition, typical mm / deg a frame, jerk
# probability; None = that hard sequence as it is), render options.
PHOTO_CONDITIONS = {
    "handheld": ("hand-held in clutter (10 things, a third in the object's own texture or colour)",
                 ("hard", "handheld", None), ["--clutter", "10"]),
    "slow": ("slow hand-held motion (1.5 mm and 0.5 deg a frame, no jerks), clutter",
             ("hard", "slow", ("1.5", "0.5", "0")), ["--clutter", "6"]),
    "light": ("hand-held, a key light that sweeps around and dims, clutter",
              ("hard2", "handheld", None), ["--clutter", "6", "--moving-light"]),
}
PHOTO_SAMPLES = 10  # path-tracing samples per pixel: a visibly grainy frame, like a webcam's
PHOTO_QUICK = dict(objects=["can", "toy"], conditions=["handheld"])


def photo_source(data, obj, cond):
    """The generated sequence whose trajectory and ground truth a photo sequence re-renders."""
    set_name, source_cond, slow = PHOTO_CONDITIONS[cond][1]
    if slow is None:
        return hard_sequence(data, obj, source_cond, HARD_FRAMES, set_name)
    # A trajectory the hard section has not: slow and smooth (generate_sequence's own frames are
    # only a by-product here).
    seed = sequence_seed("photo", obj, cond)
    base = list(HARD_BASE)
    for flag, value in zip(("--typical-translation-mm", "--typical-rotation-deg", "--jerk-probability"), slow):
        base[base.index(flag) + 1] = value
    return generated_sequence(data, obj, os.path.join(data, "photo_source", obj, cond), HARD_FRAMES, seed,
                              BACKGROUNDS[seed % len(BACKGROUNDS)], base, [],
                              "trajectory photo_source/%s/%s" % (obj, cond))


def photo_sequence(data, obj, cond, repo):
    source = photo_source(data, obj, cond)
    seed = sequence_seed("photo", obj, cond)
    folder = os.path.join(data, "photo", obj, cond)
    clutter = HARD_BACKGROUNDS["clutter"]
    cmd = ["blender", "-b", "--factory-startup", "-noaudio", "-P", os.path.join(repo, "scripts", "photoreal_render.py"),
           "--", "--source", source, "--model", os.path.join(data, "models", HARD_OBJECTS[obj]["model"] + ".obj"),
           "--background", os.path.join(PHOTOS, BACKGROUNDS[(seed // 3) % len(BACKGROUNDS)]),
           "--clutter-texture", os.path.join(PHOTOS, clutter[seed % len(clutter)]),
           "--output", folder, "--samples", PHOTO_SAMPLES, "--seed", seed] + PHOTO_CONDITIONS[cond][2]
    return cached_run(cmd, folder, "path-tracing photo/%s/%s (Blender Cycles, ~4 min)" % (obj, cond))


# ---------------------------------------------------------------------------------------------
# Noise section: how much of a difference between two configurations is chance
# ---------------------------------------------------------------------------------------------
# The tracker is chaotic on the hard sequences: a lost track, a re-acquisition or a re-anchoring
# depends on near-ties, so a change too small to matter (an initial pose 1 mm off) moves a
# sequence's AUC by several points and the section's by tenths. Each configuration of NOISE_PRESETS
# is tracked again on both hard sets from NOISE_DRAWS initial poses perturbed by
# NOISE_TRANSLATION_MM and NOISE_ROTATION_DEG about a seeded random axis (draw 0: unperturbed).
# paper on its first NOISE_TRACK_FRAMES frames: ~30 min of the section's ~1 h
NOISE_PRESETS = ["realtime", "klt_only", "paper"]
NOISE_DRAWS = 5
NOISE_TRANSLATION_MM = 1.0
NOISE_ROTATION_DEG = 0.25


def perturbed_sequence(data, source, set_name, obj, cond, draw):
    """`source` with its initial pose (first line of pose.txt) moved by a seeded perturbation;
    the frames, K.txt, visible.txt and the ground truth of the other frames are links to or
    copies of the source's. Draw 0 is the source itself."""
    if draw == 0:
        return source
    folder = os.path.join(data, "noise", set_name, obj, cond, "draw%d" % draw)
    os.makedirs(folder, exist_ok=True)
    for name in os.listdir(source):
        if name in ("pose.txt", "generated_by.txt"):
            continue
        link = os.path.join(folder, name)
        if not os.path.lexists(link):
            os.symlink(os.path.join(source, name), link)
    lines = [l for l in open(os.path.join(source, "pose.txt")) if l.strip() and not l.startswith("#")]
    v = [float(x) for x in lines[0].split()]
    rotation = [v[0:3], v[3:6], v[6:9]]  # row-major object_to_camera rotation, then translation
    rng = random.Random(zlib.crc32(("%s/%s/%s/%d" % (set_name, obj, cond, draw)).encode()))

    def unit():
        u = [rng.gauss(0.0, 1.0) for _ in range(3)]
        n = math.sqrt(sum(x * x for x in u))
        return [x / n for x in u]
    axis, direction = unit(), unit()
    a, (x, y, z) = math.radians(NOISE_ROTATION_DEG), axis
    k = [[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]]
    k2 = [[sum(k[i][m] * k[m][j] for m in range(3)) for j in range(3)] for i in range(3)]
    turn = [[(i == j) + math.sin(a) * k[i][j] + (1 - math.cos(a)) * k2[i][j] for j in range(3)]
            for i in range(3)]  # Rodrigues
    turned = [[sum(turn[i][m] * rotation[m][j] for m in range(3)) for j in range(3)] for i in range(3)]
    first = [e for row in turned for e in row] + [
        v[9 + i] + 1e-3 * NOISE_TRANSLATION_MM * direction[i] for i in range(3)]
    with open(os.path.join(folder, "pose.txt"), "w") as f:
        f.write(" ".join("%.17g" % x for x in first) + "\n" + "".join(lines[1:]))
    return folder


def run_noise(args, configs, runner, data, docs_dir, tmp):
    # NOISE_PRESETS and every --variant: a candidate change is judged against its own spread.
    chosen = [c for c in configs if c[0] in NOISE_PRESETS or c in args.variant]
    start = datetime.datetime.now(datetime.timezone.utc)
    load_start, t0 = os.getloadavg()[0], time.time()
    sets = ["hard", "hard2"]
    objects, conditions = list(HARD_OBJECTS), list(HARD_CONDITIONS)
    folders = {(s, o, c): hard_sequence(data, o, c, HARD_FRAMES, s) for s in sets for o in objects for c in conditions}
    gen_s = time.time() - t0
    rows = []
    for config in chosen:
        for draw in range(NOISE_DRAWS):
            for (s, o, c), source in folders.items():
                folder = perturbed_sequence(data, source, s, o, c, draw)
                label = "%s_draw%d" % (config[0], draw)
                if config[0] in runner.reuse:  # --reuse realtime: every draw of it
                    runner.reuse.add(label)
                cap = NOISE_TRACK_FRAMES.get(config[1])
                r = runner.track("noise", (label, config[1], config[2]), "%s/%s/%s" % (s, o, c), folder,
                                 os.path.join(data, "models", HARD_OBJECTS[o]["model"] + ".obj"),
                                 max_frames=min(cap, HARD_FRAMES) if cap else None)
                if not r:
                    continue
                score_visible(r, source)
                r.update(preset=config[0], draw=draw, set=s, object=o, condition=c)
                rows.append(r)
            log("noise %-10s draw %d: AUC %s" % (config[0], draw, fmt(weighted_auc(
                [r for r in rows if r["preset"] == config[0] and r["draw"] == draw]))))
    duration, load_end = time.time() - t0, os.getloadavg()[0]

    def spread(values, with_range=True):
        """mean +- sample sd, and the range unless with_range is False."""
        values = [v for v in values if v is not None]
        if not values:
            return "-"
        mean = sum(values) / len(values)
        sd = (sum((v - mean) ** 2 for v in values) / max(1, len(values) - 1)) ** 0.5
        text = "%.2f +- %.2f" % (mean, sd)
        return text + (" (%.2f .. %.2f)" % (min(values), max(values)) if with_range else "")

    L = header_lines("Noise section", args, start, duration, gen_s, load_start, load_end, [
        "- **Mode:** %s on both hard sets (48 sequences x %d frames), %d draws of the initial pose each "
        "(draw 0 unperturbed; the others %.2g mm and %.2g deg off, seeded); tracked frames per sequence: %s" % (
            ", ".join(c[0] for c in chosen), HARD_FRAMES, NOISE_DRAWS, NOISE_TRANSLATION_MM, NOISE_ROTATION_DEG,
            ", ".join("%s %d" % (c[0], min(NOISE_TRACK_FRAMES.get(c[1], HARD_FRAMES), HARD_FRAMES)) for c in chosen))])
    L.append("How much of a difference between two configurations on the hard sections is chance. The "
             "tracker is chaotic there: a lost track, a re-acquisition or a re-anchoring turns on near-ties, "
             "so an initial pose a millimetre off (far below any detector's error) moves single sequences by "
             "several AUC points. Read one run's differences (the other sections) against the spread below: a "
             "change smaller than about two standard deviations of its section's AUC is not shown to matter "
             "by one run. A candidate tracked here (`--variant`) is judged by its paired difference from "
             "the default on the same draws, which is far less noisy.\n")
    L.append("### AUC of each draw\n")
    L.append("| preset | set | " + " | ".join("draw %d" % d for d in range(NOISE_DRAWS)) + " | mean +- sd (min .. max) |")
    L.append("|---|---|" + "---|" * (NOISE_DRAWS + 1))
    for c in chosen:
        for s in sets + ["both"]:
            sel = [r for r in rows if r["preset"] == c[0] and (s == "both" or r["set"] == s)]
            per_draw = [weighted_auc([r for r in sel if r["draw"] == d]) for d in range(NOISE_DRAWS)]
            L.append("| %s | %s | %s | %s |" % (c[0], s, " | ".join(fmt(a) for a in per_draw), spread(per_draw)))
    # A candidate against the default on the same draws: the draws' perturbations are shared, so the
    # per-draw difference is far less noisy than either score.
    reference = next((c for c in chosen if c[0] == DEFAULT_PRESETS[0]), None)
    if reference and len(chosen) > 1:
        L.append("\n### Paired difference from %s (both sets, same draws)\n" % reference[0])
        L.append("Each draw's AUC minus %s's on the same draw. A mean beyond about two standard deviations "
                 "divided by the square root of %d (the draws) is a real difference.\n" % (reference[0], NOISE_DRAWS))
        L.append("| preset | " + " | ".join("draw %d" % d for d in range(NOISE_DRAWS)) + " | mean +- sd |")
        L.append("|---|" + "---|" * (NOISE_DRAWS + 1))
        for c in chosen:
            if c is reference:
                continue
            diffs = []
            for d in range(NOISE_DRAWS):
                a = weighted_auc([r for r in rows if r["preset"] == c[0] and r["draw"] == d])
                b = weighted_auc([r for r in rows if r["preset"] == reference[0] and r["draw"] == d])
                diffs.append(None if a is None or b is None else a - b)
            L.append("| %s | %s | %s |" % (c[0], " | ".join("%+.2f" % x if x is not None else "-" for x in diffs),
                                         spread(diffs, with_range=False)))
    # Presets tracked on fewer frames (paper: NOISE_TRACK_FRAMES) against the others on the same first
    # frames, per object: issue 10's "at least paper's on every object", as a mean over the draws.
    caps = sorted({min(NOISE_TRACK_FRAMES.get(c[1], HARD_FRAMES), HARD_FRAMES) for c in chosen})
    if len(caps) > 1:
        n = caps[0]

        def per_draw(label, **kw):
            return [first_frames_auc([r for r in rows if r["preset"] == label and r["draw"] == d
                             and all(r[k] == v for k, v in kw.items())], n) for d in range(NOISE_DRAWS)]
        L.append("\n### Per object on the first %d frames (both sets; mean +- sd over the draws)\n" % n)
        L.append("Every preset on the first %d frames of each sequence (the frames the slowest preset tracks), "
                 "so that they compare; the paired rows are each draw's difference from %s on the same "
                 "draw and frames.\n" % (n, reference[0] if reference else "-"))
        L.append("| preset | " + " | ".join(objects) + " | **all** |")
        L.append("|---|" + "---|" * (len(objects) + 1))
        for c in chosen:
            L.append("| %s | %s | **%s** |" % (c[0], " | ".join(spread(per_draw(c[0], object=o), with_range=False)
                                                               for o in objects),
                                               spread(per_draw(c[0]), with_range=False)))
        if reference:
            for c in chosen:
                if c is reference:
                    continue
                cells = []
                for kw in [dict(object=o) for o in objects] + [{}]:
                    a, b = per_draw(reference[0], **kw), per_draw(c[0], **kw)
                    cells.append(spread([x - y for x, y in zip(a, b) if x is not None and y is not None],
                                        with_range=False))
                L.append("| %s - %s | %s |" % (reference[0], c[0], " | ".join(cells)))
        L.append("")
    L.append("\n### Spread per condition (both sets; mean +- sd over the draws)\n")
    L.append("| preset | " + " | ".join(conditions) + " |")
    L.append("|---|" + "---|" * len(conditions))
    for c in chosen:
        cells = []
        for cond in conditions:
            sel = [r for r in rows if r["preset"] == c[0] and r["condition"] == cond]
            cells.append(spread([weighted_auc([r for r in sel if r["draw"] == d]) for d in range(NOISE_DRAWS)], with_range=False))
        L.append("| %s | %s |" % (c[0], " | ".join(cells)))
    L.append("\n### Spread of single sequences\n")
    L.append("Standard deviation of a sequence's AUC over the draws: median and largest over the 48 sequences.\n")
    L.append("| preset | median sd | largest sd (sequence) |")
    L.append("|---|---|---|")
    for c in chosen:
        sds = []
        for key in folders:
            values = [r["auc"] for r in rows if r["preset"] == c[0] and (r["set"], r["object"], r["condition"]) == key
                      and r["auc"] is not None]
            if len(values) >= 2:
                mean = sum(values) / len(values)
                sds.append(((sum((v - mean) ** 2 for v in values) / (len(values) - 1)) ** 0.5, "/".join(key)))
        sds.sort()
        if sds:
            L.append("| %s | %.2f | %.2f (%s) |" % (c[0], sds[len(sds) // 2][0], sds[-1][0], sds[-1][1]))
    L.append("")
    return L, rows


HARD_DESCRIPTION = (
    "Rendered by `generate_sequence`'s scene render (CPU rasterizer), 640x480, fx = 525 px, "
    "30 fps. Every sequence: hand-held motion (a damped random walk of the velocity with random "
    "jerks (5 % of the frames), at most 30 mm and 8 deg a frame; steady motion 5 mm and 1.5 deg per axis and frame "
    "(standard deviation)), Blinn-Phong "
    "highlights, cast shadows (shadow map) on the object, the distractors and the wall carrying "
    "a real photograph, motion blur over a 1/60 s shutter (6 sub-frame renders along the "
    "trajectory), Gaussian noise (sigma 3) and JPEG (quality 85). The conditions add:\n")
PHOTO_DESCRIPTION = (
    "Path-traced by Blender's Cycles on the CPU (`scripts/photoreal_render.py`, %d samples per pixel, "
    "no denoising), 640x480, fx = 525 px, 30 fps, along the trajectories (and with the ground truth) "
    "of generated sequences: the object (its texture or colour, glossy) in front of a diffusely lit "
    "real photograph, with clutter between them (boxes, cylinders, spheres; a third wearing the "
    "object's own texture or colour, a third another photograph), an area key light and a dim fill, "
    "soft shadows on the clutter and the photograph, inter-reflections, true motion blur over a "
    "1/60 s shutter, depth of field (f/8, focused on the median depth), sampling noise, a camera's "
    "filmic tone curve and JPEG (quality 90). Nothing of it is what the tracker was tuned on. "
    "The conditions:\n" % PHOTO_SAMPLES)


# ---------------------------------------------------------------------------------------------
# Far section: the hard rendering with the object 0.9-1.3 m away (the hard sets: 0.35-0.6 m)
# ---------------------------------------------------------------------------------------------
# An object on a table seen from a robot's head is often 40-130 px across: few corners, a short
# outline, and a depth that a pixel of silhouette width moves by 1-3 % of the distance.
FAR_DISTANCE = ["--distance-min", "0.9", "--distance-max", "1.3"]
FAR_CONDITIONS = {
    "handheld": ("hand-held, 0.9-1.3 m away", FAR_DISTANCE),
    "clutter": ("clutter + own-colour distractors, 0.9-1.3 m away", FAR_DISTANCE + ["--distractors", "3"]),
}


def variant_sequence(data, set_name, conditions, obj, cond, frames):
    """One sequence of a section of the hard rendering with its own conditions (run_hard_variant),
    rendered into data/<set_name>/<obj>/<cond> unless it is there."""
    seed = sequence_seed(set_name, obj, cond)
    backgrounds = HARD_BACKGROUNDS.get(cond, BACKGROUNDS)
    return generated_sequence(data, obj, os.path.join(data, set_name, obj, cond), frames, seed,
                              backgrounds[seed % len(backgrounds)], HARD_BASE, conditions[cond][1],
                              "rendering %s/%s/%s" % (set_name, obj, cond))


def run_hard_variant(args, configs, runner, data, docs_dir, tmp, set_name, conditions, frames,
                     quick_condition, objects=None):
    """A section of the hard rendering with its own conditions (name: (title, generate_sequence
    options on top of HARD_BASE)), frames and seeds (tagged set_name), rendered into
    data/<set_name>/<object>/<condition> (cached) and tracked as the hard sections are; `objects`
    (default: the hard sections')."""
    if objects is None:
        objects = HARD_QUICK["objects"] if args.quick else list(HARD_OBJECTS)
    chosen = [quick_condition] if args.quick else list(conditions)
    frames = HARD_QUICK["frames"] if args.quick else (args.hard_frames or frames)

    folders = lambda: {(o, c): variant_sequence(data, set_name, conditions, o, c, frames)  # rendered in run_hard
                       for o in objects for c in chosen}
    return run_hard(args, configs, runner, data, docs_dir, tmp, set_name=set_name, folders=folders,
                    condition_titles=conditions, folder_frames=frames)


def run_far(args, configs, runner, data, docs_dir, tmp):
    return run_hard_variant(args, configs, runner, data, docs_dir, tmp, "far", FAR_CONDITIONS, HARD_FRAMES,
                            "handheld")


# ---------------------------------------------------------------------------------------------
# Large-mesh section: a 150k-face model in the hard rendering
# ---------------------------------------------------------------------------------------------
# A user's model is often a scan or a detailed CAD export of 100k faces or more; `paper` needs
# 3 s a frame on one. The hard objects have at most 4.8k faces, so a cost that grows with the
# faces (silhouettes, contour extraction) does not show there. The bike of the OPT-style section
# (150k faces, 0.56 m across, thin tubes and spokes: much background inside its outline) moved by
# the hard sections' hand, 1.0-1.4 m away (its size in the image as the hard objects').
LARGE_OBJECTS = {"bike": dict(model="bike", kind="textured, 150k faces, thin parts", render=[])}
LARGE_DISTANCE = ["--distance-min", "1.0", "--distance-max", "1.4"]
LARGE_CONDITIONS = {
    "handheld": ("hand-held, 1.0-1.4 m away", LARGE_DISTANCE),
    "occlusion": ("moving occluder, 1.0-1.4 m away", LARGE_DISTANCE + ["--occluder-passes", "2"]),
    "leave": ("leaves and re-enters, 1.0-1.4 m away",
              LARGE_DISTANCE + ["--leave-start", "25", "--leave-frames", "14"]),
}
LARGE_FRAMES = 60


def run_large(args, configs, runner, data, docs_dir, tmp):
    return run_hard_variant(args, configs, runner, data, docs_dir, tmp, "large", LARGE_CONDITIONS,
                            LARGE_FRAMES, "leave", objects=list(LARGE_OBJECTS))


# ---------------------------------------------------------------------------------------------
# Long section: the hard rendering over 300 frames (the hard sets: 80)
# ---------------------------------------------------------------------------------------------
# Real sequences run for hundreds of frames (RBOT's 1001, a robot's minutes). An 80-frame sequence
# cannot show a wrong pose held with confidence for hundreds of frames: the colour and energy
# levels learned on it, the anchors KLT keeps on it. Two conditions mix the hard ones, each
# rendered over LONG_FRAMES frames with seeds of their own.
LONG_FRAMES = 300
LONG_CONDITIONS = {
    "clutter": ("hand-held, clutter + own-colour distractors, 300 frames", ["--distractors", "3"]),
    "mixed": ("hand-held, a moving occluder (5 passes) and lighting changes, 300 frames",
              ["--occluder-passes", "5", "--lighting-changes"]),
}


def run_long(args, configs, runner, data, docs_dir, tmp):
    return run_hard_variant(args, configs, runner, data, docs_dir, tmp, "long", LONG_CONDITIONS, LONG_FRAMES,
                            "clutter")


# ---------------------------------------------------------------------------------------------
# Slow section: precision on slow footage, with the model exact and 3 % off
# ---------------------------------------------------------------------------------------------
# On slow real footage a refinement can only add error where the keypoints are already right: the
# contour energy's optimum moves with every shape error of the model (rounded edges, a scan's or a
# CAD model's few millimetres), and it is flat along what the outline does not fix. This section
# tracks slow hand-held motion (1.5 mm and 0.5 deg a frame, no jerks) in clutter, near and small
# in the image, each with the very mesh of the render and with the mesh 3 % off (MISMATCH_SCALE,
# as the mismatch section), and reports the median rotation and translation errors beside the AUC:
# what `klt_only` beats `paper` by on such footage (issue 11's notes: 1.0 against 5.4 deg).
SLOW_MOTION = ["--typical-translation-mm", "1.5", "--typical-rotation-deg", "0.5", "--jerk-probability", "0",
               "--distractors", "3"]
SLOW_CONDITIONS = {
    "near": ("slow hand-held in clutter, 0.35-0.6 m away", SLOW_MOTION),
    "small": ("slow hand-held in clutter, 0.7-1.0 m away", SLOW_MOTION + ["--distance-min", "0.7",
                                                                       "--distance-max", "1.0"]),
}
SLOW_MODELS = {"exact": "the render's own mesh", "off": "the mesh 3 %% off (%s)" % " x ".join(
    "%g" % f for f in MISMATCH_SCALE)}


def read_poses(path):
    """A pose file of 12 numbers a line (row-major R, then t in metres); None for a blank line."""
    poses = []
    for line in open(path):
        if line.startswith("#"):
            continue
        v = [float(x) for x in line.split()]
        poses.append((v[:9], v[9:12]) if len(v) >= 12 else None)
    return poses


def pose_errors(estimated, truth):
    """Per frame: (rotation error deg, translation error mm) of `estimated` against `truth`
    (read_poses); frame 0 (the given pose) and frames without a pose left out."""
    out = []
    for i in range(1, min(len(estimated), len(truth))):
        if estimated[i] is None or truth[i] is None:
            continue
        (ra, ta), (rb, tb) = estimated[i], truth[i]
        if not all(math.isfinite(x) for x in ra + ta):
            continue
        cosine = (sum(a * b for a, b in zip(ra, rb)) - 1.0) / 2.0  # trace(Ra^T Rb) = sum Ra_ij Rb_ij
        rotation = math.degrees(math.acos(max(-1.0, min(1.0, cosine))))
        out.append((rotation, 1000.0 * math.sqrt(sum((a - b) ** 2 for a, b in zip(ta, tb)))))
    return out


def run_slow(args, configs, runner, data, docs_dir, tmp):
    objects = HARD_QUICK["objects"] if args.quick else list(HARD_OBJECTS)
    conditions = ["near"] if args.quick else list(SLOW_CONDITIONS)
    frames = HARD_QUICK["frames"] if args.quick else (args.hard_frames or HARD_FRAMES)
    start = datetime.datetime.now(datetime.timezone.utc)
    load_start, t0 = os.getloadavg()[0], time.time()
    folders = {(o, c): variant_sequence(data, "slow", SLOW_CONDITIONS, o, c, frames)
               for o in objects for c in conditions}
    gen_s = time.time() - t0
    rows = []
    for config in configs:
        for (o, c), folder in folders.items():
            exact = ensure_model(data, HARD_OBJECTS[o]["model"])
            for m, (model, score_model) in (("exact", (exact, None)),
                                            ("off", (mismatched_model(data, HARD_OBJECTS[o]["model"]), exact))):
                r = runner.track("slow", config, "%s/%s_%s" % (o, c, m), folder, model, score_model=score_model)
                if not r:
                    continue
                score_visible(r, folder)
                errors = pose_errors(read_poses(r["poses_file"]), read_poses(os.path.join(folder, "pose.txt")))
                r.update(object=o, condition=c, model=m,
                         rotation_deg=median([e[0] for e in errors]), translation_mm=median([e[1] for e in errors]))
                log("slow %-20s %-7s %-6s %-5s AUC %5.2f  rotation %5.2f deg  translation %5.1f mm" % (
                    config[0], o, c, m, r["auc"] or 0, r["rotation_deg"] or -1, r["translation_mm"] or -1))
                rows.append(r)
    duration = time.time() - t0

    def sel(**kw):
        return [r for r in rows if all(r[k] == v for k, v in kw.items())]
    labels = [cfg[0] for cfg in configs]
    L = header_lines("Slow section (precision: slow motion, the model exact and 3 % off)", args, start, duration,
                     gen_s, load_start, os.getloadavg()[0], [
                         "- **Mode:** %s (%d objects x %d conditions x 2 models x %d frames, every preset on "
                         "every frame)" % ("quick" if args.quick else "full", len(objects), len(conditions), frames)])
    L.append(HARD_DESCRIPTION)
    L.append("Here the motion is slow: the hard rendering with %s. Each sequence is tracked twice: with %s "
             "(`exact`) and with %s (`off`: a 3 %% shape error, as a CAD model or a scan has; scored against "
             "the true shape). Where the keypoints are right, a refinement that follows the contour's "
             "optimum adds the model's error: this section is where that shows.\n" % (
                 " ".join(SLOW_MOTION), SLOW_MODELS["exact"], SLOW_MODELS["off"]))
    for c in conditions:
        L.append("- `%s`: %s (`%s`)" % (c, SLOW_CONDITIONS[c][0], " ".join(SLOW_CONDITIONS[c][1])))
    L.append("")
    cells = [(c, m) for c in conditions for m in SLOW_MODELS]
    L.append("### AUC per condition and model\n")
    L.append("| preset | " + " | ".join("%s, %s" % cm for cm in cells) + " | **exact** | **off** |")
    L.append("|---|" + "---|" * (len(cells) + 2))
    for p in labels:
        L.append("| %s | %s | **%s** | **%s** |" % (
            p, " | ".join(fmt(weighted_auc(sel(preset=p, condition=c, model=m))) for c, m in cells),
            fmt(weighted_auc(sel(preset=p, model="exact"))), fmt(weighted_auc(sel(preset=p, model="off")))))
    L.append("")
    L.append("### Median rotation / translation error\n")
    L.append("Per sequence the median over its frames (the given frame left out), then the median over the "
             "sequences of the cell: deg / mm.\n")
    L.append("| preset | object | " + " | ".join("%s, %s" % cm for cm in cells) + " |")
    L.append("|---|---|" + "---|" * len(cells))
    for p in labels:
        for o in objects + ["**all**"]:
            chosen = (lambda **kw: sel(preset=p, **kw)) if o == "**all**" else (lambda **kw: sel(preset=p, object=o, **kw))
            L.append("| %s | %s | %s |" % (p, o, " | ".join(
                "%s / %s" % (fmt(median([r["rotation_deg"] for r in chosen(condition=c, model=m)])),
                             fmt(median([r["translation_mm"] for r in chosen(condition=c, model=m)]), 1))
                for c, m in cells)))
    L.append("")
    L.append("### AUC per object and model\n")
    L.append("| preset | " + " | ".join("%s, %s" % (o, m) for o in objects for m in SLOW_MODELS) + " |")
    L.append("|---|" + "---|" * (len(objects) * len(SLOW_MODELS)))
    for p in labels:
        L.append("| %s | %s |" % (p, " | ".join(fmt(weighted_auc(sel(preset=p, object=o, model=m)))
                                              for o in objects for m in SLOW_MODELS)))
    L.append("")
    L.append("### Speed\n")
    L.append("Median of the per-sequence median `track()` time per frame (first frame excluded), ms.\n")
    L += speed_table(rows, configs, [(o, sel(object=o)) for o in objects])
    L.append("")
    return L, rows


def run_photo(args, configs, runner, data, docs_dir, tmp):
    if shutil.which("blender") is None:
        return ["## Photo section (path-traced)\n", "Not run: `blender` is missing (Debian package blender).\n"], []
    objects = PHOTO_QUICK["objects"] if args.quick else list(HARD_OBJECTS)
    conditions = PHOTO_QUICK["conditions"] if args.quick else list(PHOTO_CONDITIONS)
    folders = lambda: {(o, c): photo_sequence(data, o, c, args.repo) for o in objects for c in conditions}
    return run_hard(args, configs, runner, data, docs_dir, tmp, set_name="photo", folders=folders,
                    condition_titles={c: (PHOTO_CONDITIONS[c][0], PHOTO_CONDITIONS[c][2]) for c in conditions})


def run_hard(args, configs, runner, data, docs_dir, tmp, set_name="hard", folders=None, condition_titles=None,
             models=None, folder_frames=HARD_FRAMES):
    """The hard sections (and the photo and mismatch sections, given their folders of
    folder_frames frames, condition titles and models: object -> (the model the tracker is given,
    the true one it is scored against)). `folders`: {(object, condition): folder}, or a function
    returning it that renders what is missing (called here, so that the header's time
    "generating missing data" includes it)."""
    condition_titles = condition_titles or HARD_CONDITIONS
    frames = HARD_QUICK["frames"] if args.quick else (args.hard_frames or HARD_FRAMES)
    start = datetime.datetime.now(datetime.timezone.utc)
    load_start, t0 = os.getloadavg()[0], time.time()
    if callable(folders):
        folders = folders()
    if folders is None:
        objects = HARD_QUICK["objects"] if args.quick else list(HARD_OBJECTS)
        conditions = HARD_QUICK["conditions"] if args.quick else list(HARD_CONDITIONS)
        folders = {(o, c): hard_sequence(data, o, c, frames, set_name) for o in objects for c in conditions}
    else:
        objects = list(dict.fromkeys(o for o, _ in folders))
        conditions = list(dict.fromkeys(c for _, c in folders))
        frames = folder_frames
    gen_s = time.time() - t0
    rows = []
    for config in configs:
        for (o, c), folder in folders.items():
            model, score_model = (models or {}).get(
                o, (os.path.join(data, "models", object_spec(o)["model"] + ".obj"), None))
            r = runner.track(set_name, config, "%s/%s" % (o, c), folder, model, score_model=score_model)
            if not r:
                continue
            visible = score_visible(r, folder)
            good = r.get("good")
            r["good_scored"] = None if good is None or len(good) != len(r["errors"]) else [
                (g, e / r["diameter_m"]) for g, e, v in zip(good, r["errors"], visible) if v >= HARD_MIN_VISIBLE]
            r.update(object=o, condition=c,
                     normalized_errors=[e / r["diameter_m"] for e in r["visible_errors"] if e is not None])
            log("%s %-20s %-7s %-10s AUC %5.2f  median %7.1f ms" % (set_name, config[0], o, c, r["auc"] or 0, r["median_ms"]))
            rows.append(r)
    duration = time.time() - t0
    load_end = os.getloadavg()[0]

    def sel(**kw):
        return [r for r in rows if all(r[k] == v for k, v in kw.items())]
    labels = [c[0] for c in configs]
    L = header_lines(SECTION_TITLES[set_name], args, start, duration, gen_s, load_start, load_end, [
        "- **Mode:** %s (%d objects x %d conditions x %d frames, every preset on every frame)" % (
            "quick" if args.quick else "full", len(objects), len(conditions), frames)])
    L.append(PHOTO_DESCRIPTION if set_name == "photo" else HARD_DESCRIPTION)
    if set_name == "mismatch":
        L.append("The frames of the `%s` set, tracked with each model stretched by %s along its x, y, z "
                 "axes about its bounding box centre (a 3 %% shape error, as a CAD model or a scan has) and "
                 "scored against the true shape (`track_sequence --score-model`): the contour energy's "
                 "optimum is no longer the true pose, as on real video.\n" % (
                     MISMATCH_SET, " x ".join("%g" % f for f in MISMATCH_SCALE)))
    for c in conditions:
        L.append("- `%s`: %s (`%s`)" % (c, condition_titles[c][0], " ".join(condition_titles[c][1]) or "nothing more"))
    L.append("")
    L.append("Objects: %s. AUC of 20 over the frames where at least %d %% of the object's silhouette is "
             "in the image and not occluded (`visible.txt` of each sequence).\n" % (
                 ", ".join("`%s` (%s)" % (o, object_spec(o)["kind"]) for o in objects), 100 * HARD_MIN_VISIBLE))
    L.append("### AUC per condition\n")
    L.append("| preset | " + " | ".join(conditions) + " | **all** |")
    L.append("|---|" + "---|" * (len(conditions) + 1))
    for p in labels:
        L.append("| %s | %s | **%s** |" % (p, " | ".join(fmt(weighted_auc(sel(preset=p, condition=c))) for c in conditions),
                                           fmt(weighted_auc(sel(preset=p)))))
    L.append("")
    n = HARD_FIRST_FRAMES

    def first_n(rr):
        return first_frames_auc(rr, n)
    if frames > n:
        L.append("Every preset on the first %d frames of each sequence (before most losses).\n" % n)
        L.append("| preset | " + " | ".join(conditions) + " | **all** |")
        L.append("|---|" + "---|" * (len(conditions) + 1))
        for p in labels:
            L.append("| %s | %s | **%s** |" % (p, " | ".join(fmt(first_n(sel(preset=p, condition=c))) for c in conditions),
                                               fmt(first_n(sel(preset=p)))))
        L.append("")
    L.append("### AUC per object\n")
    L.append("| preset | " + " | ".join(objects) + " |")
    L.append("|---|" + "---|" * len(objects))
    for p in labels:
        L.append("| %s | %s |" % (p, " | ".join(fmt(weighted_auc(sel(preset=p, object=o))) for o in objects)))
    L.append("")
    if frames > n:
        L.append("Per object on the first %d frames of each sequence:\n" % n)
        L.append("| preset | " + " | ".join(objects) + " |")
        L.append("|---|" + "---|" * len(objects))
        for p in labels:
            L.append("| %s | %s |" % (p, " | ".join(fmt(first_n(sel(preset=p, object=o))) for o in objects)))
        L.append("")
    L.append("### AUC per object and condition\n")
    L.append("| preset | object | " + " | ".join(conditions) + " |")
    L.append("|---|---|" + "---|" * len(conditions))
    for p in labels:
        for o in objects:
            L.append("| %s | %s | %s |" % (p, o, " | ".join(fmt(weighted_auc(sel(preset=p, object=o, condition=c)))
                                                              for c in conditions)))
    L.append("")
    keys = session_counts(rows)
    if keys:
        L.append("### Losses and re-acquisitions (tracking session)\n")
        leave_args = condition_titles.get("leave", HARD_CONDITIONS["leave"])[1]
        L.append("A loss: the session's state goes from tracking to lost; re-acquired: it tracks again "
                 "before the sequence ends; *within %d frames*: counted from the loss, so the frames the "
                 "object spends outside the image (leave: %s) or behind the occluder count too; *right*: "
                 "of those, the ones whose pose at the re-acquisition frame is off by less than %g "
                 "diameters (a re-acquisition on a distractor counts in the other columns); *within %d "
                 "frames of being visible, right* (issue 11's measure): of the losses after which the "
                 "object is visible again (the share is of those), the ones re-acquired right within "
                 "%d frames of the first frame at or after the loss where at least %d %% of it is in the image and "
                 "not occluded (when it leaves the image after the loss, of the frame it is back from; a "
                 "re-acquisition before that frame is on something else, never right); the "
                 "median is over the re-acquired losses.\n"
                 % (REACQUIRE_WITHIN_FRAMES, leave_args[leave_args.index("--leave-frames") + 1],
                    WRONG_POSE_DIAMETERS, REACQUIRE_WITHIN_FRAMES, REACQUIRE_WITHIN_FRAMES,
                    round(100 * HARD_MIN_VISIBLE)))
        L.append("| preset | condition | " + " | ".join(keys) + " |")
        L.append("|---|---|" + "---|" * len(keys))
        for p in labels:
            for c in conditions:
                L.append("| %s | %s | %s |" % (p, c, " | ".join(session_cells(sel(preset=p, condition=c)))))
            L.append("| %s | **all** | %s |" % (p, " | ".join(session_cells(sel(preset=p)))))
        L.append("")
    verdicts = [(p, verdict_cells(sel(preset=p))) for p in labels]
    if any(cells for _, cells in verdicts):
        L.append("### Can the verdict be trusted? (tracking session)\n")
        L.append("Each frame's verdict is what `~status` tells a ROS user (the trace's `good`). Over the "
                 "scored frames: *good but wrong* are frames reported good whose pose is off by at least "
                 "%g x the diameter (what a robot acts on wrongly); *AUC lost on them* is what those frames "
                 "cost the preset's AUC of 20; *bad but right* are frames reported bad whose pose was within "
                 "that bound. Presets whose results predate the trace show no row.\n" % WRONG_POSE_DIAMETERS)
        L.append("| preset | " + " | ".join(VERDICT_COLUMNS) + " |")
        L.append("|---|" + "---|" * len(VERDICT_COLUMNS))
        for p, cells in verdicts:
            if cells:
                L.append("| %s | %s |" % (p, " | ".join(cells)))
        L.append("")
    L.append("### Speed\n")
    L.append("Median of the per-sequence median `track()` time per frame (first frame excluded), ms.\n")
    L += speed_table(rows, configs, [(o, sel(object=o)) for o in objects])
    L.append("")
    # The slow frames of the default presets and of the variants asked for on the command line
    # (--variant: e.g. the large-mesh section's full mesh), not of every built-in variant.
    asked = {v[0] for v in args.variant}
    L += tail_table(rows, [c for c in configs if c[0] in DEFAULT_PRESETS or c[0] in asked],
                    [(o, sel(object=o)) for o in objects])
    L += stage_table(rows, configs, [(o, sel(object=o)) for o in objects])
    for name in os.listdir(docs_dir):
        if name.startswith(set_name + "_") and name.endswith(".png"):
            os.remove(os.path.join(docs_dir, name))
    plot(os.path.join(docs_dir, "%s_overall.png" % set_name), "%s: success vs k" % SECTION_TITLES[set_name],
         [(p, [e for r in sel(preset=p) for e in r["normalized_errors"]]) for p in labels], tmp)
    for c in conditions:
        plot(os.path.join(docs_dir, "%s_%s.png" % (set_name, c)), "%s: %s" % (set_name, condition_titles[c][0]),
             [(p, [e for r in sel(preset=p, condition=c) for e in r["normalized_errors"]]) for p in labels], tmp)
    L.append("### Success curves\n")
    L.append("![%s](benchmarks/%s_overall.png)\n" % (set_name, set_name))
    L.append("Per condition: " + ", ".join("[%s](benchmarks/%s_%s.png)" % (c, set_name, c) for c in conditions) + ".\n")
    return L, rows


# ---------------------------------------------------------------------------------------------
# Real section
# ---------------------------------------------------------------------------------------------
def real_sequence(data, name):
    spec = REAL[name]
    folder = os.path.join(data, "real", name)
    cmd = ["rosrun", "klt_contour_tracker", "convert_visp_sequence", "--images", spec["images"],
           "--prefix", spec["prefix"], "--camera-xml", spec["xml"], "--output-dir", folder]
    cmd += ["--camera-poses", spec["poses"]] if "poses" in spec else ["--initial-pose", spec["pose"]]
    return cached_run(cmd, folder, "converting ViSP sequence %s" % name)


def alignment(folder, model, poses, out_base):
    proc = rosrun("contour_alignment", "--sequence", folder, "--model", model, "--poses", poses,
                  "--summary-json", out_base + ".alignment.json", "--per-frame", out_base + ".alignment.txt",
                  capture_output=True, text=True)
    if proc.returncode != 0:
        log("contour_alignment failed on %s: %s" % (folder, proc.stderr.strip()[-300:]))
        return None
    return json.load(open(out_base + ".alignment.json"))


# contour_alignment's `held` needs the given initial pose to stand out from chance on its own
# frame: mbt-depth/castel's coarse CAD model scores 0.218 there against a chance of 0.220, so
# any frame of a right track may fall below its threshold.
ALIGNMENT_MIN_FIRST_OVER_CHANCE = 1.2


def alignment_judges_holding(frozen):
    """Whether contour_alignment's held_frames means anything for a sequence: its given initial
    pose (`frozen`'s first frame) aligns at least ALIGNMENT_MIN_FIRST_OVER_CHANCE x chance."""
    return bool(frozen) and frozen["first_frame_alignment"] >= ALIGNMENT_MIN_FIRST_OVER_CHANCE * frozen["chance"]


def run_real(args, configs, runner, data, docs_dir, tmp):
    if not os.path.isdir(VISP):
        return ["## Real section\n", "Not run: %s is missing (Debian package visp-images-data).\n" % VISP], []
    names = REAL_QUICK if args.quick else list(REAL)
    start = datetime.datetime.now(datetime.timezone.utc)
    load_start, t0 = os.getloadavg()[0], time.time()
    folders = {n: real_sequence(data, n) for n in names}
    gen_s = time.time() - t0
    rows, reference = [], {}
    for n in names:
        folder = folders[n]
        # References: the initial pose held still (what "no tracking" scores) and, with ground
        # truth, the true poses.
        pose_lines = [l for l in open(os.path.join(folder, "pose.txt")) if l.strip() and not l.startswith("#")]
        frames = sequence_frames(folder)
        frozen = os.path.join(tmp, "%s_frozen.txt" % n)
        with open(frozen, "w") as f:
            f.write(pose_lines[0] * frames)
        base = os.path.join(tmp, n)
        reference[n] = {"frozen": alignment(folder, REAL[n]["model"], frozen, base + "_frozen")}
        if len(pose_lines) > 1:
            reference[n]["truth"] = alignment(folder, REAL[n]["model"], os.path.join(folder, "pose.txt"), base + "_truth")
    for config in configs:
        for n in names:
            r = runner.track("real", config, n, folders[n], REAL[n]["model"])
            if not r:
                continue
            r.update(object=n, scored_frames=len(r["errors"]) if "auc" in r else 0)
            if "auc" in r:
                r["normalized_errors"] = [e / r["diameter_m"] for e in r["errors"]]
            a = alignment(folders[n], REAL[n]["model"], r["poses_file"],
                          os.path.join(runner.results, "real", config[0], n))
            r["alignment"] = a
            log("real %-20s %-12s held %s/%s  alignment %s%s" % (
                config[0], n, a and a["held_frames"], a and a["frames"], fmt(a and a["alignment"], 3),
                "  AUC %.2f" % r["auc"] if "auc" in r else ""))
            rows.append(r)
    duration = time.time() - t0
    load_end = os.getloadavg()[0]
    labels = [c[0] for c in configs]

    def get(p, n):
        return next((r for r in rows if r["preset"] == p and r["object"] == n), None)
    L = header_lines("Real section", args, start, duration, gen_s, load_start, load_end,
                     ["- **Mode:** %s (%s)" % ("quick" if args.quick else "full", ", ".join(names))])
    L.append("ViSP's test sequences from the Debian package `visp-images-data` (`%s`), converted by "
             "`convert_visp_sequence` (frames, K from the tracker's XML, ViSP's cMo = our "
             "object_to_camera), tracked with ViSP's own `.cao` CAD models:\n" % VISP)
    for n in names:
        L.append("- `%s`: %s" % (n, REAL[n]["title"]))
    L.append("")
    L.append("**Where there is no ground truth the scores are NOT AUC.** `alignment` (`contour_alignment`): "
             "the model's silhouette rendered at the tracked pose; the fraction of its outline pixels "
             "within 2 px of a Canny edge of the frame (Gaussian sigma 1, thresholds 40/100), averaged "
             "over the frames, 0..1. `chance` is the fraction of all pixels within 2 px of an edge (what "
             "a randomly placed outline scores). `held` is the number of frames before the first 5 "
             "consecutive frames whose alignment is below max(chance, half the first frame's). "
             "`frozen` holds the initial pose for every frame (no tracking) and `truth` scores the "
             "ground-truth poses where they exist. Where the given initial pose itself scores less "
             "than %.1f x chance on its own frame (the model's outline and the frame's edges do not "
             "separate), `held` cannot tell a held track from a lost one and is shown as `n/a`.\n"
             % ALIGNMENT_MIN_FIRST_OVER_CHANCE)
    L.append("| sequence | frames | chance | frozen: held / alignment | truth: alignment | " +
             " | ".join("%s: held / alignment" % p for p in labels) + " |")
    L.append("|---|---|---|---|---|" + "---|" * len(labels))
    for n in names:
        fr = reference[n].get("frozen")
        tr = reference[n].get("truth")
        judged = alignment_judges_holding(fr)

        def held(a):
            return "%s / %s" % (a["held_frames"] if judged else "n/a", fmt(a["alignment"], 3))
        cells = []
        for p in labels:
            a = (get(p, n) or {}).get("alignment")
            cells.append(held(a) if a else "-")
        L.append("| %s | %s | %s | %s | %s | %s |" % (
            n, fr["frames"] if fr else "-", fmt(fr and fr["chance"], 3),
            held(fr) if fr else "-", fmt(tr and tr["alignment"], 3), " | ".join(cells)))
    L.append("")
    gt = [n for n in names if any("auc" in r for r in rows if r["object"] == n)]
    if gt:
        L.append("With ground truth (AUC of 20, every frame):\n")
        L.append("| sequence | " + " | ".join(labels) + " |")
        L.append("|---|" + "---|" * len(labels))
        for n in gt:
            L.append("| %s | %s |" % (n, " | ".join(fmt((get(p, n) or {}).get("auc")) for p in labels)))
        L.append("")
    keys = session_counts(rows)
    if keys:
        L.append("Losses and re-acquisitions (tracking session):\n")
        L.append("| preset | sequence | " + " | ".join(keys) + " |")
        L.append("|---|---|" + "---|" * len(keys))
        for p in labels:
            for n in names:
                r = get(p, n)
                if r:
                    L.append("| %s | %s | %s |" % (p, n, " | ".join(session_cells([r]))))
        L.append("")
    L.append("Speed (median `track()` time per frame, ms):\n")
    L += speed_table(rows, configs, [(n, [r for r in rows if r["object"] == n]) for n in names])
    L.append("")
    for name in os.listdir(docs_dir):
        if name.startswith("real_") and name.endswith(".png"):
            os.remove(os.path.join(docs_dir, name))
    if gt:
        plot(os.path.join(docs_dir, "real_castle_simu.png"), "Castle-simu (ground truth): success vs k",
             [(p, [e for r in rows if r["preset"] == p and r["object"] in gt for e in r.get("normalized_errors", [])])
              for p in labels], tmp)
        L.append("![Castle-simu](benchmarks/real_castle_simu.png)\n")
    return L, rows


# ---------------------------------------------------------------------------------------------
# OPT-style section
# ---------------------------------------------------------------------------------------------
def all_opt_sequences():
    return [(g, s) for g in GROUPS_SPEED for s in range(1, 6)] + [(g, 3) for g in GROUPS_SINGLE]


def seq_name(group, speed):
    return "%s_s%d" % (group, speed) if group in GROUPS_SPEED else group


def opt_sequence(data, obj, group, speed):
    spec = OBJECTS[obj]
    folder = os.path.join(data, "sequences", obj, seq_name(group, speed))
    seed = sequence_seed(obj, group, speed)
    background = os.path.join(PHOTOS, BACKGROUNDS[seed % len(BACKGROUNDS)])
    cmd = ["rosrun", "klt_contour_tracker", "generate_sequence",
           "--model", ensure_model(data, spec["model"]), "--output-dir", folder,
           "--frames", str(spec["frames"]), "--width", str(spec["width"]),
           "--height", str(spec["height"]), "--fx", str(spec["fx"]), "--motion", group,
           "--speed", str(speed), "--seed", str(seed), "--noise-sigma", str(NOISE_SIGMA),
           "--motion-blur-samples", str(MOTION_BLUR_SAMPLES), "--background", background]
    return cached_run(cmd, folder, "rendering %s/%s" % (obj, seq_name(group, speed)))


def startup_run(folder, model, preset, cache_dir):
    """track_sequence on two frames: its summary (startup_ms: tracker + visibility table, faces)."""
    out = os.path.join(cache_dir, "startup.json")
    cmd = ["rosrun", "klt_contour_tracker", "track_sequence", "--sequence", folder, "--model", model,
           "--preset", preset, "--param", "visibility_cache_dir=" + cache_dir, "--max-frames", "2",
           "--summary-json", out, "--quiet"]
    if subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode != 0:
        return {}
    with open(out) as f:
        return json.load(f)


def startup_table(configs, objects, folders, sequences, data, tmp):
    """First start (the visibility table built) and a cached start, per object and preset."""
    presets = [c[1] for c in configs if c[1] == c[0]]  # plain presets (ablations share them)
    L = ["### Start-up (visibility table)\n",
         "Wall time of the session's start before the first frame (tracker, visibility table), ms: "
         "`first` with an empty cache (the table is built), `cached` the second start on the same "
         "model (read from `visibility_cache_dir`). One run each, measured after the tracking "
         "runs above. `klt_only` has no visibility table.\n"]
    L.append("| object | faces | " + " | ".join("%s first | %s cached" % (p, p) for p in presets) + " |")
    L.append("|---|---|" + "---|---|" * len(presets))
    for o in objects:
        model = os.path.join(data, "models", OBJECTS[o]["model"] + ".obj")
        folder = folders[(o,) + tuple(sequences[0])]
        cells = []
        faces = None
        for p in presets:
            cache = os.path.join(tmp, "startup_cache_%s_%s" % (o, p))
            subprocess.run(["rm", "-rf", cache])
            os.makedirs(cache)
            first = startup_run(folder, model, p, cache)
            cached = startup_run(folder, model, p, cache)
            cells += [fmt(first.get("startup_ms"), 0), fmt(cached.get("startup_ms"), 0)]
            faces = faces or first.get("faces")
        L.append("| %s | %s | %s |" % (o, faces or "-", " | ".join(cells)))
    L.append("")
    return L


def run_opt(args, configs, runner, data, docs_dir, tmp):
    global QUICK_FRAMES
    if args.frames:
        for spec in OBJECTS.values():
            spec["frames"] = args.frames
        QUICK_FRAMES = min(QUICK_FRAMES, args.frames)
    objects = args.objects.split(",") if args.objects else (QUICK_OBJECTS if args.quick else list(OBJECTS))
    unknown = [o for o in objects if o not in OBJECTS]
    if unknown:
        sys.exit("unknown object(s) %s; known: %s" % (", ".join(unknown), ", ".join(OBJECTS)))
    sequences = QUICK_SEQUENCES if args.quick else all_opt_sequences()
    start = datetime.datetime.now(datetime.timezone.utc)
    load_start, t0 = os.getloadavg()[0], time.time()
    folders = {(o, g, s): opt_sequence(data, o, g, s) for o in objects for g, s in sequences}
    gen_s = time.time() - t0
    rows = []
    for config in configs:
        for obj in objects:
            frames = QUICK_FRAMES if args.quick else OBJECTS[obj]["frames"]
            if args.track_frames:
                frames = min(frames, args.track_frames)
            for group, speed in sequences:
                r = runner.track("opt", config, "%s/%s" % (obj, seq_name(group, speed)), folders[(obj, group, speed)],
                                 os.path.join(data, "models", OBJECTS[obj]["model"] + ".obj"), max_frames=frames)
                if not r:
                    continue
                r.update(object=obj, group=group, speed=speed,
                         normalized_errors=[e / r["diameter_m"] for e in r["errors"]])
                log("opt  %-20s %-10s %-14s AUC %5.2f  median %7.1f ms" % (
                    config[0], obj, seq_name(group, speed), r["auc"], r["median_ms"]))
                rows.append(r)
    duration = time.time() - t0
    load_end = os.getloadavg()[0]
    presets = [c[0] for c in configs]

    def sel(**kw):
        return [r for r in rows if all(
            (r[k] in v) if isinstance(v, (list, tuple, set)) else r[k] == v for k, v in kw.items())]

    groups = [g for g in GROUPS_SPEED + GROUPS_SINGLE if any(s[0] == g for s in sequences)]
    speeds = sorted({s for g, s in sequences if g in GROUPS_SPEED})
    slow = [s for s in speeds if s <= 2]
    fast = [s for s in speeds if s >= 4]

    for name in os.listdir(docs_dir):
        if name.endswith(".png") and (name == "overall.png" or name.startswith(("group_", "object_"))):
            os.remove(os.path.join(docs_dir, name))
    plot(os.path.join(docs_dir, "overall.png"), "OPT-style: success vs k", [
        ("%s %s" % (p, o), [e for r in sel(preset=p, object=o) for e in r["normalized_errors"]])
        for p in presets for o in objects], tmp)
    for g in groups:
        plot(os.path.join(docs_dir, "group_%s.png" % g), GROUP_TITLES[g], [
            ("%s %s" % (p, o), [e for r in sel(preset=p, object=o, group=g) for e in r["normalized_errors"]])
            for p in presets for o in objects], tmp)
    for o in objects:
        for p in presets:
            plot(os.path.join(docs_dir, "object_%s_%s.png" % (o, p)), "%s, preset %s" % (o, p), [
                (g, [e for r in sel(preset=p, object=o, group=g) for e in r["normalized_errors"]])
                for g in groups], tmp)

    partial = args.track_frames or any(o not in objects for o in OBJECTS)
    mode = "quick" if args.quick else ("partial" if partial else "full")
    extra = ["- **Mode:** %s (%d objects x %d sequences x %s frames)" % (
        mode, len(objects), len(sequences),
        str(QUICK_FRAMES if not args.track_frames else min(QUICK_FRAMES, args.track_frames)) if args.quick
        else "/".join("%s %d" % (o, min(OBJECTS[o]["frames"], args.track_frames or 10**9)) for o in objects))]
    skipped = [o for o in OBJECTS if o not in objects]
    if skipped and not args.quick:
        extra.append("- **Not run here:** %s" % ", ".join(skipped))
    L = header_lines("OPT-style section", args, start, duration, gen_s, load_start, load_end, extra)
    L.append("The paper's Sec. 4 evaluates on the OPT dataset, which cannot be downloaded here: these "
             "sequences imitate its motion groups and speeds (moderate, clean shading, one photograph "
             "as background: easy; the hard section is the harder test). Cells aggregate every frame "
             "of their sequences.\n")
    L.append("### AUC per object (cf. the paper's Table 1)\n")
    L.append("| object | faces | resolution | " + " | ".join(presets) + " |")
    L.append("|---|---|---|" + "---|" * len(presets))
    for o in objects:
        r0 = sel(object=o)
        if not r0:
            continue
        L.append("| %s | %d | %dx%d | %s |" % (o, r0[0]["faces"], r0[0]["width"], r0[0]["height"],
                 " | ".join(fmt(weighted_auc(sel(preset=p, object=o))) for p in presets)))
    L.append("| **all** | | | %s |" % " | ".join("**%s**" % fmt(weighted_auc(sel(preset=p))) for p in presets))
    L.append("")
    L.append("### AUC per motion group (cf. Table 2)\n")
    L.append("| preset | object | " + " | ".join(GROUP_TITLES[g] for g in groups) + " |")
    L.append("|---|---|" + "---|" * len(groups))
    for p in presets:
        for o in objects + ["all"]:
            cells = []
            for g in groups:
                rr = sel(preset=p, group=g) if o == "all" else sel(preset=p, object=o, group=g)
                cells.append(fmt(weighted_auc(rr)))
            L.append("| %s | %s | %s |" % (p, "**all**" if o == "all" else o, " | ".join(cells)))
    L.append("")
    if slow and fast:
        L.append("### Slow vs fast motion (cf. Table 3)\n")
        L.append("Translation and rotation groups only; slow = speed %s, fast = speed %s (of 1-5).\n" % (
            "/".join(map(str, slow)), "/".join(map(str, fast))))
        L.append("| preset | object | " + " | ".join("%s slow | %s fast" % (GROUP_TITLES[g], GROUP_TITLES[g])
                                                    for g in GROUPS_SPEED if g in groups) + " |")
        L.append("|---|---|" + "---|---|" * len([g for g in GROUPS_SPEED if g in groups]))
        for p in presets:
            for o in objects + ["all"]:
                cells = []
                for g in GROUPS_SPEED:
                    if g not in groups:
                        continue
                    for sp in (slow, fast):
                        rr = sel(preset=p, group=g, speed=sp) if o == "all" else sel(preset=p, object=o, group=g, speed=sp)
                        cells.append(fmt(weighted_auc(rr)))
                L.append("| %s | %s | %s |" % (p, "**all**" if o == "all" else o, " | ".join(cells)))
        L.append("")
    L.append("### Speed (cf. Table 4)\n")
    L.append("Median of the per-sequence median tracking time per frame (first frame excluded), ms.\n")
    L += speed_table(rows, configs, [(o, sel(object=o)) for o in objects])
    L.append("")
    L += tail_table(rows, [c for c in configs if c[0] in DEFAULT_PRESETS], [(o, sel(object=o)) for o in objects])

    def growth(p):
        vga = [(r0["faces"], median([r["median_ms"] for r in sel(preset=p, object=o)]))
               for o in objects for r0 in sel(preset=p, object=o)[:1] if r0["width"] == 640]
        if len(vga) < 2:
            return "-"
        small, large = min(vga), max(vga)
        return "%.1fx (%d to %d faces)" % (large[1] / small[1], small[0], large[0]) if small[1] else "-"
    L.append("Growth from the smallest to the largest mesh at 640x480 (the paper: 2.4x): " + ", ".join(
        "%s %s" % (p, growth(p)) for p in presets) + ".\n")
    L += stage_table(rows, configs, [(o, sel(object=o)) for o in objects])
    L += startup_table(configs, objects, folders, sequences, data, tmp)
    L.append("### Other metrics\n")
    L.append("| preset | object | success 5 cm / 5 deg | mean ADD, mm | extrapolated frames |")
    L.append("|---|---|---|---|---|")
    for p in presets:
        for o in objects:
            rr = sel(preset=p, object=o)
            if not rr:
                continue
            n = sum(r["scored_frames"] for r in rr)
            L.append("| %s | %s | %.3f | %.2f | %d of %d |" % (
                p, o, sum(r["success_5cm5deg"] * r["scored_frames"] for r in rr) / n,
                sum(r["mean_add_mm"] * r["scored_frames"] for r in rr) / n,
                sum(r.get("extrapolated_frames", 0) for r in rr), sum(r["frames"] for r in rr)))
    failed = len(presets) * len(objects) * len(sequences) - len(rows)
    if failed:
        L.append("\n**%d tracking runs failed** (see the log of scripts/benchmark.sh)." % failed)
    L.append("")
    L.append("### Success curves\n")
    L.append("![all sequences](benchmarks/overall.png)\n")
    L.append("Per motion group: " + ", ".join("[%s](benchmarks/group_%s.png)" % (GROUP_TITLES[g], g) for g in groups) + ".\n")
    L.append("Per object (curves per group): " + ", ".join(
        "[%s %s](benchmarks/object_%s_%s.png)" % (o, p, o, p) for o in objects for p in presets) + ".\n")
    L.append("Objects (`make_benchmark_models`, see `models/README.md`): `can` (~2.5k faces), `chest` "
             "(~4.7k), `rock` (~22k), `bike` (~150k); `can_1080p` is the can at 1920x1080 (same field of "
             "view). Sequences (`generate_sequence`, 30 Hz): the four motion groups at speeds 1-5, flash "
             "light, moving light and free motion (speed 3), over a real photograph, with %d-sample "
             "motion blur and noise sigma %.0f; quick mode: %s, %s, %d frames each.\n" % (
                 MOTION_BLUR_SAMPLES, NOISE_SIGMA, " and ".join(QUICK_OBJECTS),
                 ", ".join(seq_name(g, s) for g, s in QUICK_SEQUENCES), QUICK_FRAMES))
    return L, rows


# ---------------------------------------------------------------------------------------------
# The page and the README headline
# ---------------------------------------------------------------------------------------------
README_BEGIN = "<!-- benchmark headline: written by scripts/benchmark.sh -->"
README_END = "<!-- end of benchmark headline -->"


def first_table(lines, heading):
    i = next((k for k, l in enumerate(lines) if l.startswith(heading)), None)
    if i is None:
        return []
    table = []
    for l in lines[i + 1:]:
        if l.startswith("|"):
            table.append(l)
        elif table:
            break
    return table


def write_page(repo, docs_dir):
    fragments = {}
    for s in SECTIONS:
        path = os.path.join(docs_dir, "%s.md" % s)
        if os.path.exists(path):
            fragments[s] = open(path).read().rstrip("\n").splitlines()
    L = ["# Benchmarks\n",
         "Generated by `scripts/benchmark.sh`; do not edit by hand (each section is kept in "
         "`docs/benchmarks/<section>.md` and re-written when that section is run). Sections: "
         "[hard](#hard-section) (hand-held motion, clutter, untextured/open objects, occlusion, "
         "leaving the image, lighting, sensor effects), [hard, second seed set](#hard-section-second-seed-set) "
         "(the same with other trajectories and backgrounds), [mismatch](#mismatch-section-the-model-3--off-the-object) "
         "(the hard frames tracked with a model 3 % off the object, as on real video), "
         "[camera rate](#camera-rate-section-the-hard-set-as-a-live-30-hz-camera) (the hard set as a live "
         "30 Hz camera: frames dropped while the tracker is busy), [far](#far-section-small-in-the-image-09-13-m-away) "
         "(the hard rendering with the object 0.9-1.3 m away, 40-130 px across), "
         "[large mesh](#large-mesh-section-a-150k-face-model-in-the-hard-rendering) (a 150k-face "
         "model moved by the same hand: what a scan's face count costs), [long](#long-section-300-frames-a-sequence-what-a-wrong-hold-costs) "
         "(the hard rendering over 300 frames: a wrong pose held with confidence costs the rest of the sequence), "
         "[slow](#slow-section-precision-slow-motion-the-model-exact-and-3--off) (precision on slow footage, "
         "with the model exact and 3 % off: median rotation and translation errors), [photo](#photo-section-path-traced) (hard "
         "trajectories path-traced by Blender: shading, shadows, blur and noise the tracker was not tuned on), "
         "[noise](#noise-section) (how much of a "
         "difference is chance: the hard sets tracked from slightly perturbed initial poses), "
         "[real](#real-section) (ViSP's real sequences: "
         "frames held and contour alignment, not AUC, plus a simulated sequence with ground truth), "
         "[OPT-style](#opt-style-section) (the paper's motion groups, easy).\n",
         "AUC: area under the success curve (success rate in percent vs error threshold k, k in "
         "[0, 0.2] of the object diameter), out of 20, as in the paper (Sec. 4.1). Each section "
         "states its command, date, code version, duration and the machine's load.\n"]
    for s in SECTIONS:
        if s in fragments:
            L += fragments[s] + [""]
    with open(os.path.join(repo, "docs", "benchmarks.md"), "w") as f:
        f.write("\n".join(L) + "\n")
    # README headline: the hard section's per-condition table first, then the OPT-style one.
    readme = os.path.join(repo, "README.md")
    text = open(readme).read()
    if README_BEGIN not in text or README_END not in text:
        return
    block = [README_BEGIN, ""]
    if "hard" in fragments:
        mode = next((l[len("- **Mode:** "):] for l in fragments["hard"] if l.startswith("- **Mode:**")), "")
        date = next((l[len("- **Date:** "):] for l in fragments["hard"] if l.startswith("- **Date:**")), "")
        block += ["**Hard section** (hand-held motion up to 30 mm / 8 deg a frame, clutter, untextured and "
                  "open objects, occlusion, leaving the image, lighting, sensor effects), AUC of 20; %s, %s:"
                  % (date, mode), ""]
        block += first_table(fragments["hard"], "### AUC per condition") + [""]
        block += first_table(fragments["hard"], "### AUC per object") + [""]
    if "photo" in fragments:
        block += ["**Photo section** (the hard trajectories path-traced by Blender's Cycles: soft shadows, "
                  "true motion blur, depth of field, sampling noise, clutter in the object's own colours), "
                  "AUC of 20:", ""]
        block += first_table(fragments["photo"], "### AUC per condition") + [""]
        block += first_table(fragments["photo"], "### AUC per object") + [""]
    if "opt" in fragments:
        block += ["**OPT-style section** (the paper's motion groups; easy), AUC of 20:", ""]
        block += first_table(fragments["opt"], "### AUC per object") + [""]
    block += ["All tables (the real-footage section too), timings and plots: "
              "[docs/benchmarks.md](docs/benchmarks.md).", ""]
    if "hard" in fragments:
        block += ["![hard section success curves](docs/benchmarks/hard_overall.png)", ""]
    block.append(README_END)
    start = text.index(README_BEGIN)
    end = text.index(README_END) + len(README_END)
    with open(readme, "w") as f:
        f.write(text[:start] + "\n".join(block) + text[end:])


def parse_variant(text):
    """LABEL:PRESET[:name=value,name=value...]"""
    parts = text.split(":", 2)
    if len(parts) < 2 or not parts[0] or not parts[1]:
        raise argparse.ArgumentTypeError("--variant takes LABEL:PRESET[:name=value,...], got %r" % text)
    params = {}
    if len(parts) == 3 and parts[2]:
        for kv in parts[2].split(","):
            if "=" not in kv:
                raise argparse.ArgumentTypeError("--variant parameter %r is not name=value" % kv)
            k, v = kv.split("=", 1)
            params[k.strip()] = v.strip()
    return (parts[0], parts[1], params)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--section", action="append", choices=SECTIONS, help="repeatable; default: all")
    ap.add_argument("--quick", action="store_true", help="part of each section")
    ap.add_argument("--preset", action="append", dest="presets", help="repeatable; default: %s and the "
                    "ABLATIONS whose preset exists" % ", ".join(DEFAULT_PRESETS))
    ap.add_argument("--variant", action="append", type=parse_variant, default=[],
                    help="LABEL:PRESET:name=value,... a preset with parameter overrides (repeatable)")
    ap.add_argument("--objects", help="OPT-style section: comma-separated subset of " + ",".join(OBJECTS))
    ap.add_argument("--frames", type=int, help="OPT-style section: frames per sequence (generated and tracked)")
    ap.add_argument("--track-frames", type=int, help="OPT-style section: track only the first N frames")
    ap.add_argument("--hard-frames", type=int, help="hard section: frames per sequence [%d]" % HARD_FRAMES)
    ap.add_argument("--reuse", action="append", default=[], metavar="LABEL",
                    help="take this configuration's results from the previous run (data/benchmark/results) "
                         "instead of tracking again, e.g. a slow preset whose code did not change (repeatable)")
    ap.add_argument("--repo", required=True)
    ap.add_argument("--command", required=True, help="the command line, for the report")
    args = ap.parse_args()
    sections = [s for s in SECTIONS if s in (args.section or SECTIONS)]
    known = available_presets()
    if args.presets:
        bad = [p for p in args.presets if p not in known]
        if bad:
            ap.error("unknown preset(s) %s; this build knows %s" % (", ".join(bad), ", ".join(known)))
        configs = [(p, p, {}) for p in args.presets]
    else:
        configs = [(p, p, {}) for p in DEFAULT_PRESETS if p in known]
        configs += [a for a in ABLATIONS if a[1] in known]
    for v in args.variant:
        if v[1] not in known:
            ap.error("--variant %s: unknown preset %s" % (v[0], v[1]))
        configs.append(v)
    repo = args.repo
    # Taken now, before anything runs: the code the binaries were built from, not whatever
    # HEAD is when the run ends (commits may land during a long run).
    os.environ.setdefault("KCT_BENCH_CODE", code_version(repo))
    data = os.path.join(os.environ.get("KCT_DATA", os.path.join(repo, "data")), "benchmark")
    results = os.path.join(data, "results")
    docs_dir = os.path.join(repo, "docs", "benchmarks")
    tmp = os.path.join(data, "tmp")
    for d in (results, docs_dir, tmp):
        os.makedirs(d, exist_ok=True)
    log("benchmark: sections %s, configurations %s, load %.2f" % (
        ", ".join(sections), ", ".join(c[0] for c in configs), os.getloadavg()[0]))
    args.data_results = results
    runner = Runner(repo, results, args.reuse)
    t0 = time.time()
    summary = []
    for s in sections:
        ts = time.time()
        run = {"hard": run_hard, "hard2": lambda *a: run_hard(*a, set_name="hard2"), "mismatch": run_mismatch,
               "camera": run_camera, "far": run_far, "large": run_large, "long": run_long, "slow": run_slow,
               "photo": run_photo, "noise": run_noise,
               "real": run_real, "opt": run_opt}[s]
        lines, rows = run(args, configs, runner, data, docs_dir, tmp)
        with open(os.path.join(docs_dir, "%s.md" % s), "w") as f:
            f.write("\n".join(lines) + "\n")
        with open(os.path.join(results, "rows_%s%s.json" % (s, "_quick" if args.quick else "")), "w") as f:
            json.dump([{k: v for k, v in r.items() if k not in ("errors", "normalized_errors", "visible_errors")}
                       for r in rows], f, indent=1)
        for c in configs:
            if not any(r["preset"] == c[0] for r in rows):
                continue  # not tracked in this section (noise: NOISE_PRESETS and --variant only)
            summary.append("%s %-22s AUC %s (%.1f min for the section)" % (
                s, c[0], fmt(weighted_auc([r for r in rows if r["preset"] == c[0]])), (time.time() - ts) / 60))
    write_page(repo, docs_dir)
    log("benchmark: wrote docs/benchmarks.md (%.1f min, load at end %.2f)" % ((time.time() - t0) / 60, os.getloadavg()[0]))
    for line in summary:
        log("benchmark: " + line)


if __name__ == "__main__":
    main()
