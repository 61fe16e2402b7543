#!/usr/bin/env python3
"""OPT-style benchmark driver (called by scripts/benchmark.sh, which installs, builds and
sources the workspace first). Generates the missing models and sequences under
data/benchmark (cached; deterministic from seeds), tracks every sequence with each preset,
and writes docs/benchmarks.md with the AUC tables (like the paper's Tables 1-3), the frame
times and PNG success curves in docs/benchmarks/. Python standard library only.
"""
import argparse
import shutil
import tempfile
import datetime
import json
import os
import platform
import shlex
import subprocess
import sys
import time
import zlib

GROUPS_SPEED = ["xy", "z", "inplane", "outofplane"]
GROUPS_SINGLE = ["flash", "movinglight", "free"]
GROUP_TITLES = {"xy": "x-y translation", "z": "z translation", "inplane": "in-plane rotation",
                "outofplane": "out-of-plane rotation", "flash": "flash light",
                "movinglight": "moving light", "free": "free motion"}
PHOTOS = "/usr/share/doc/opencv-doc/examples/data"
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


def log(msg):
    print("[%s] %s" % (time.strftime("%H:%M:%S"), msg), file=sys.stderr, flush=True)


def all_sequences():
    return [(g, s) for g in GROUPS_SPEED for s in range(1, 6)] + [(g, 3) for g in GROUPS_SINGLE]


def seq_name(group, speed):
    return "%s_s%d" % (group, speed) if group in GROUPS_SPEED else group


def ensure_model(data, model):
    path = os.path.join(data, "models", model + ".obj")
    if not os.path.exists(path):
        log("models: generating %s" % model)
        subprocess.run(["rosrun", "klt_contour_tracker", "make_benchmark_models", "--output-dir",
                        os.path.join(data, "models"), "--only", model], check=True)
    return path


def ensure_sequence(data, obj, group, speed):
    spec = OBJECTS[obj]
    folder = os.path.join(data, "sequences", obj, seq_name(group, speed))
    seed = zlib.crc32(("%s/%s/%d" % (obj, group, speed)).encode()) % 100000 + 1
    background = os.path.join(PHOTOS, BACKGROUNDS[seed % len(BACKGROUNDS)])
    cmd = ["rosrun", "klt_contour_tracker", "generate_sequence",
           "--model", ensure_model(data, spec["model"]), "--output-dir", folder,
           "--frames", str(spec["frames"]), "--width", str(spec["width"]),
           "--height", str(spec["height"]), "--fx", str(spec["fx"]), "--motion", group,
           "--speed", str(speed), "--seed", str(seed), "--noise-sigma", str(NOISE_SIGMA),
           "--motion-blur-samples", str(MOTION_BLUR_SAMPLES), "--background", background]
    stamp = os.path.join(folder, "generated_by.txt")
    wanted = " ".join(shlex.quote(c) for c in cmd) + "\n"
    if os.path.exists(stamp) and open(stamp).read() == wanted:
        return folder
    log("sequences: rendering %s/%s" % (obj, seq_name(group, speed)))
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    with open(stamp, "w") as f:
        f.write(wanted)
    return folder


def track(data, results, obj, group, speed, preset, max_frames, repo):
    spec = OBJECTS[obj]
    folder = ensure_sequence(data, obj, group, speed)
    out = os.path.join(results, preset, obj)
    os.makedirs(out, exist_ok=True)
    base = os.path.join(out, seq_name(group, speed))
    cmd = ["rosrun", "klt_contour_tracker", "track_sequence", "--sequence", folder,
           "--model", os.path.join(data, "models", spec["model"] + ".obj"), "--preset", preset,
           "--param", "visibility_cache_dir=" + os.path.join(repo, "data", "cache", "visibility"),
           "--output", base + ".poses.txt", "--summary-json", base + ".json",
           "--errors", base + ".errors.txt", "--max-frames", str(max_frames), "--quiet"]
    t0 = time.time()
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if proc.returncode != 0:
        log("FAILED %s %s/%s: %s" % (preset, obj, seq_name(group, speed), proc.stderr.strip()[-300:]))
        return None
    with open(base + ".json") as f:
        summary = json.load(f)
    with open(base + ".errors.txt") as f:
        summary["normalized_errors"] = [float(x) / summary["diameter_m"] for x in f.read().split()]
    summary.update(object=obj, group=group, speed=speed, wall_s=time.time() - t0)
    log("%-9s %-10s %-14s AUC %5.2f  median %7.1f ms" % (preset, obj, seq_name(group, speed),
                                                         summary["auc"], summary["median_ms"]))
    return summary


def startup_times(data, obj, preset, tmp):
    """Wall time of a 2-frame track_sequence run (mesh load, visibility table, first frames) with
    an empty visibility cache, then again with the cache it wrote: (first, cached) seconds."""
    spec = OBJECTS[obj]
    folder = ensure_sequence(data, obj, *all_sequences()[0])
    cache = tempfile.mkdtemp(prefix="kct_startup_", dir=tmp)
    times = []
    for _ in range(2):
        cmd = ["rosrun", "klt_contour_tracker", "track_sequence", "--sequence", folder,
               "--model", os.path.join(data, "models", spec["model"] + ".obj"), "--preset", preset,
               "--param", "visibility_cache_dir=" + cache, "--max-frames", "2", "--quiet"]
        t0 = time.time()
        proc = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        times.append(time.time() - t0 if proc.returncode == 0 else None)
    shutil.rmtree(cache, ignore_errors=True)
    log("startup   %-10s %-9s first %s s, cached %s s" % (obj, preset, fmt(times[0], 1), fmt(times[1], 1)))
    return times


STAGES = [("klt", "KLT"), ("pnp", "PnP"), ("keypoint_detection", "keypoint detection"),
          ("image", "image (pyramid, gradients)"), ("contour_extraction", "contour extraction"),
          ("energy", "energy (cues)"), ("optimizer", "optimizer")]


def weighted_auc(rows):
    """AUC over all frames of `rows` (the AUC is a per-frame mean, so this is exact)."""
    n = sum(r["scored_frames"] for r in rows)
    return sum(r["auc"] * r["scored_frames"] for r in rows) / n if n else None


def median(values):
    v = sorted(values)
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


README_BEGIN = "<!-- benchmark headline: written by scripts/benchmark.sh -->"
README_END = "<!-- end of benchmark headline -->"


def update_readme(repo, page):
    """Copies the page's per-object AUC table and run line into README.md's marked block."""
    readme = os.path.join(repo, "README.md")
    text = open(readme).read()
    if README_BEGIN not in text or README_END not in text:
        return
    lines = page.splitlines()
    table = []
    i = lines.index(next(l for l in lines if l.startswith("## AUC per object")))
    for l in lines[i + 1:]:
        if l.startswith("|"):
            table.append(l)
        elif table:
            break
    info = dict((l.split(":**")[0][4:], l.split(":**", 1)[1].strip()) for l in lines if l.startswith("- **") and ":**" in l)
    block = [README_BEGIN, "",
             "Latest results: %s run (%s), %s, %s. AUC of 20, higher is better; all tables, "
             "timings and plots in [docs/benchmarks.md](docs/benchmarks.md)." % (
                 info.get("Mode", "?").split(" ")[0], info.get("Mode", "?").split(" ", 1)[-1].strip("()"),
                 info.get("Date", "?"), info.get("Machine", "?").split(",")[0]),
             ""] + table + ["", "![success curves](docs/benchmarks/overall.png)", "", README_END]
    start = text.index(README_BEGIN)
    end = text.index(README_END) + len(README_END)
    with open(readme, "w") as f:
        f.write(text[:start] + "\n".join(block) + text[end:])


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


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--preset", action="append", dest="presets")
    ap.add_argument("--objects", help="comma-separated subset of " + ",".join(OBJECTS))
    ap.add_argument("--frames", type=int, help="frames per sequence for every object (generated and tracked)")
    ap.add_argument("--track-frames", type=int,
                    help="track only the first N frames of each sequence (no regeneration)")
    ap.add_argument("--repo", required=True)
    ap.add_argument("--command", required=True, help="the command line, for the report")
    args = ap.parse_args()
    presets = args.presets or ["realtime", "paper", "klt_only"]
    repo = args.repo
    # Taken now, before anything runs: the code the binaries were built from, not whatever
    # HEAD is when the run ends (commits may land during a long run).
    os.environ.setdefault("KCT_BENCH_CODE", code_version(repo))
    data = os.path.join(os.environ.get("KCT_DATA", os.path.join(repo, "data")), "benchmark")
    results = os.path.join(data, "results")
    docs = os.path.join(repo, "docs")
    plots = os.path.join(docs, "benchmarks")
    tmp = os.path.join(data, "tmp")
    for d in (results, plots, tmp):
        os.makedirs(d, exist_ok=True)

    if args.frames:
        for spec in OBJECTS.values():
            spec["frames"] = args.frames
        global QUICK_FRAMES
        QUICK_FRAMES = min(QUICK_FRAMES, args.frames)
    objects = args.objects.split(",") if args.objects else (QUICK_OBJECTS if args.quick else list(OBJECTS))
    unknown = [o for o in objects if o not in OBJECTS]
    if unknown:
        ap.error("unknown object(s) %s; known: %s" % (", ".join(unknown), ", ".join(OBJECTS)))
    sequences = QUICK_SEQUENCES if args.quick else all_sequences()
    start = datetime.datetime.now(datetime.timezone.utc)
    load_start = os.getloadavg()
    t0 = time.time()
    # Generate everything first so that tracking times are not mixed with rendering.
    for obj in objects:
        for group, speed in sequences:
            ensure_sequence(data, obj, group, speed)
    gen_s = time.time() - t0
    rows = []
    for preset in presets:
        for obj in objects:
            frames = QUICK_FRAMES if args.quick else OBJECTS[obj]["frames"]
            if args.track_frames:
                frames = min(frames, args.track_frames)
            for group, speed in sequences:
                r = track(data, results, obj, group, speed, preset, frames, repo)
                if r:
                    r["preset"] = preset
                    rows.append(r)
    # Start-up of the default preset per model: first start (visibility table built) and cached.
    startup = {}
    if "realtime" in presets:
        for obj in objects:
            startup[obj] = startup_times(data, obj, "realtime", tmp)
    total_s = time.time() - t0
    load_end = os.getloadavg()

    def growth(p):
        vga = [(r0["faces"], median([r["median_ms"] for r in sel(preset=p, object=o)]))
               for o in objects for r0 in sel(preset=p, object=o)[:1] if r0["width"] == 640]
        if len(vga) < 2:
            return "-"
        small, large = min(vga), max(vga)
        return "%.1fx (%d to %d faces)" % (large[1] / small[1], small[0], large[0]) if small[1] else "-"

    def sel(**kw):
        return [r for r in rows if all(
            (r[k] in v) if isinstance(v, (list, tuple, set)) else r[k] == v for k, v in kw.items())]

    groups = [g for g in GROUPS_SPEED + GROUPS_SINGLE if any(s[0] == g for s in sequences)]
    speeds = sorted({s for g, s in sequences if g in GROUPS_SPEED})
    slow = [s for s in speeds if s <= 2]
    fast = [s for s in speeds if s >= 4]

    # Plots (stale ones from an earlier run with other objects or presets go first).
    for name in os.listdir(plots):
        if name.endswith(".png"):
            os.remove(os.path.join(plots, name))
    png = []
    def add_plot(name, title, curves):
        plot(os.path.join(plots, name), title, curves, tmp)
        png.append(name)
    add_plot("overall.png", "All sequences: success vs k", [
        ("%s %s" % (p, o), [e for r in sel(preset=p, object=o) for e in r["normalized_errors"]])
        for p in presets for o in objects])
    for g in groups:
        add_plot("group_%s.png" % g, GROUP_TITLES[g], [
            ("%s %s" % (p, o), [e for r in sel(preset=p, object=o, group=g) for e in r["normalized_errors"]])
            for p in presets for o in objects])
    for o in objects:
        for p in presets:
            add_plot("object_%s_%s.png" % (o, p), "%s, preset %s" % (o, p), [
                (g, [e for r in sel(preset=p, object=o, group=g) for e in r["normalized_errors"]])
                for g in groups])

    # Page.
    partial = args.track_frames or any(o not in objects for o in OBJECTS)
    mode = "quick" if args.quick else ("partial" if partial else "full")
    L = []
    L.append("# Benchmarks\n")
    L.append("OPT-style synthetic benchmark (the paper's Sec. 4 evaluates on the OPT dataset, which "
             "cannot be downloaded here). Generated by `scripts/benchmark.sh`; do not edit by hand.\n")
    L.append("- **Mode:** %s (%d objects x %d sequences x %s frames, presets %s)" % (
        mode, len(objects), len(sequences),
        str(QUICK_FRAMES if not args.track_frames else min(QUICK_FRAMES, args.track_frames)) if args.quick
        else "/".join("%s %d" % (o, min(OBJECTS[o]["frames"], args.track_frames or 10**9)) for o in objects),
        ", ".join(presets)))
    skipped = [o for o in OBJECTS if o not in objects]
    if skipped and not args.quick:
        L.append("- **Not run here:** %s" % ", ".join(skipped))
    L.append("- **Command:** `%s`" % args.command)
    L.append("- **Date:** %s" % start.strftime("%Y-%m-%d %H:%M UTC"))
    L.append("- **Machine:** %s" % machine())
    L.append("- **Code:** %s" % code_version(repo))
    L.append("- **Duration:** %.1f min (of which %.1f min generating missing data)" % (total_s / 60, gen_s / 60))
    L.append("- **Load average** (1 min) at start / end: %.2f / %.2f on %d cores. %s" % (
        load_start[0], load_end[0], os.cpu_count(),
        "The CPU was shared with other jobs: frame times are noisy and pessimistic."
        if max(load_start[0], load_end[0]) > 0.5 * (os.cpu_count() or 1) + 0.5 else ""))
    L.append("")
    L.append("AUC: area under the success curve (success rate in percent vs error threshold k, "
             "k in [0, 0.2] of the object diameter), out of 20, as in the paper (Sec. 4.1). "
             "Cells aggregate every frame of their sequences.\n")

    L.append("## AUC per object (cf. the paper's Table 1)\n")
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

    L.append("## AUC per motion group (cf. Table 2)\n")
    L.append("| preset | object | " + " | ".join(GROUP_TITLES[g] for g in groups) + " |")
    L.append("|---|---|" + "---|" * len(groups))
    for p in presets:
        for o in objects + ["all"]:
            cells = []
            for g in groups:
                rr = sel(preset=p, group=g) if o == "all" else sel(preset=p, object=o, group=g)
                cells.append(fmt(weighted_auc(rr)))
            name = "**all**" if o == "all" else o
            L.append("| %s | %s | %s |" % (p, name, " | ".join(cells)))
    L.append("")

    if slow and fast:
        L.append("## Slow vs fast motion (cf. Table 3)\n")
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
        if len(speeds) > 2:
            L.append("### AUC per speed level (translation and rotation groups)\n")
            L.append("| preset | object | " + " | ".join("speed %d" % s for s in speeds) + " |")
            L.append("|---|---|" + "---|" * len(speeds))
            for p in presets:
                for o in objects:
                    L.append("| %s | %s | %s |" % (p, o, " | ".join(
                        fmt(weighted_auc(sel(preset=p, object=o, group=GROUPS_SPEED, speed=s))) for s in speeds)))
            L.append("")

    L.append("## Speed (cf. Table 4)\n")
    L.append("Median of the per-sequence median tracking time per frame (first frame excluded), ms.\n")
    L.append("| object | faces | resolution | " + " | ".join(presets) + " |")
    L.append("|---|---|---|" + "---|" * len(presets))
    for o in objects:
        r0 = sel(object=o)
        if not r0:
            continue
        L.append("| %s | %d | %dx%d | %s |" % (o, r0[0]["faces"], r0[0]["width"], r0[0]["height"],
                 " | ".join(fmt(median([r["median_ms"] for r in sel(preset=p, object=o)]), 1) for p in presets)))
    L.append("")

    L.append("Growth from the smallest to the largest mesh at 640x480 (the paper: 2.4x): " + ", ".join(
        "%s %s" % (p, growth(p)) for p in presets) + ".\n")

    staged = [p for p in presets if any("stage_median_ms" in r for r in sel(preset=p))]
    if staged:
        L.append("### Where the time goes\n")
        L.append("Median over the sequences of each stage's median time per frame, ms. With 2 threads the "
                 "refinement's image work runs while KLT does, so the stages may add up to more than "
                 "the frame time.\n")
        L.append("| preset | object | frame | " + " | ".join(t for _, t in STAGES) + " |")
        L.append("|---|---|---|" + "---|" * len(STAGES))
        for p in staged:
            for o in objects:
                rr = [r for r in sel(preset=p, object=o) if "stage_median_ms" in r]
                if rr:
                    L.append("| %s | %s | %s | %s |" % (p, o, fmt(median([r["median_ms"] for r in rr]), 1), " | ".join(
                        fmt(median([r["stage_median_ms"].get(k, 0.0) for r in rr]), 1) for k, _ in STAGES)))
        L.append("")
    if startup:
        L.append("### Start-up (realtime)\n")
        L.append("Wall time of a 2-frame `track_sequence` run: mesh load, visibility table, first frames; "
                 "first with an empty visibility cache, then with the table it cached, s.\n")
        L.append("| object | faces | first start | cached |")
        L.append("|---|---|---|---|")
        for o in objects:
            r0 = sel(object=o)
            L.append("| %s | %s | %s | %s |" % (o, r0[0]["faces"] if r0 else "-", fmt(startup[o][0], 1),
                                              fmt(startup[o][1], 1)))
        L.append("")

    L.append("## Other metrics\n")
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
                sum(r["extrapolated_frames"] for r in rr), sum(r["frames"] for r in rr)))
    failed = len(presets) * len(objects) * len(sequences) - len(rows)
    if failed:
        L.append("\n**%d tracking runs failed** (see the log of scripts/benchmark.sh)." % failed)
    L.append("")

    L.append("## Success curves\n")
    L.append("Success rate (percent of frames with error < k x diameter) vs k; the legend gives each "
             "curve's AUC.\n")
    L.append("![all sequences](benchmarks/overall.png)\n")
    L.append("Per motion group: " + ", ".join("[%s](benchmarks/group_%s.png)" % (GROUP_TITLES[g], g) for g in groups) + ".\n")
    L.append("Per object (curves per group): " + ", ".join(
        "[%s %s](benchmarks/object_%s_%s.png)" % (o, p, o, p) for o in objects for p in presets) + ".\n")

    L.append("## The suite\n")
    L.append("""- **Objects** (`make_benchmark_models`, see `models/README.md`): `can` (soda-can-like
  surface of revolution, ~2.5k faces), `chest` (box with barrel lid, bands, lock, ~4.7k), `rock`
  (organic displaced icosphere, ~22k), `bike` (bicycle-like frame of many tubes, ~150k); `can_1080p`
  is the can at OPT's 1920x1080 (same field of view). The paper's OPT objects have 2.6k to 176k faces.
- **Sequences** (`generate_sequence`, 30 Hz): x-y translation, z translation, in-plane rotation and
  out-of-plane rotation at speeds 1-5, flash light, moving light and free motion (speed 3), each over
  a real photograph from opencv-doc, with %d-sample motion blur (averaged sub-frame renders) and
  Gaussian sensor noise (sigma %.0f grey levels); seeded from the object, group and speed.
- **Quick mode** (`--quick`): %s, %s, %d frames each.
- Data are cached in `data/benchmark/` (git-ignored): delete it to regenerate.
""" % (MOTION_BLUR_SAMPLES, NOISE_SIGMA, " and ".join(QUICK_OBJECTS),
       ", ".join(seq_name(g, s) for g, s in QUICK_SEQUENCES), QUICK_FRAMES))
    with open(os.path.join(docs, "benchmarks.md"), "w") as f:
        f.write("\n".join(L) + "\n")
    update_readme(repo, "\n".join(L))
    with open(os.path.join(results, "rows_%s.json" % mode), "w") as f:
        json.dump([{k: v for k, v in r.items() if k != "normalized_errors"} for r in rows], f, indent=1)
    log("benchmark: wrote %s (%d runs, %.1f min)" % (os.path.join(docs, "benchmarks.md"), len(rows), total_s / 60))
    for p in presets:
        log("benchmark: overall AUC %s = %s" % (p, fmt(weighted_auc(sel(preset=p)))))


if __name__ == "__main__":
    main()
