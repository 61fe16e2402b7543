#!/usr/bin/env python3
"""The developers' loop for a candidate change: the noise section's runs (both hard sets, the
initial-pose draws), tracked by any track_sequence binary (a core-only build of a branch, say)
with --param overrides, and a paired comparison of two such runs on the same draws. Scored with
benchmark.py's own functions (auc, weighted_auc, reacquired_right_once_visible), so a dev-loop
figure is the benchmark's. The data are the benchmark's (`scripts/benchmark.sh --section noise`
generates them, or `dev_loop.py generate` under the built workspace's environment).

  dev_loop.py generate [--long | --slow]                 # the hard sets (or the long / slow section)
  dev_loop.py run LABEL [--binary PATH] [--draws 0,1] [--sets hard] [--objects can,toy]
                  [--conditions occlusion] [--preset realtime] [--jobs 2] [--mismatch]
                  [--param NAME=VALUE ...] [--camera-rate 30] [--hypotheses] [--long | --slow]
  dev_loop.py compare CANDIDATE BASE                      # paired per draw, per condition, runs
  dev_loop.py reach LABEL                                 # a --hypotheses run: what re-acquisition
                                                          # had to choose from, against the truth
  dev_loop.py truth [--binary PATH] [--sets hard,hard2] [--objects ...] [--conditions ...]
                                                          # does the refinement hold the true pose?

Runs are written under $KCT_DATA/benchmark/dev/LABEL/ (poses, errors, trace, summary per run)
and $KCT_DATA/benchmark/dev/LABEL.json (the scored rows)."""
import argparse
import concurrent.futures
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark as B  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# As benchmark.py: the data under $KCT_DATA/benchmark.
DATA = os.path.join(os.environ.get("KCT_DATA", os.path.join(ROOT, "data")), "benchmark")
DEV = os.path.join(DATA, "dev")


def generate(a):
    for o in B.HARD_OBJECTS:
        B.ensure_model(DATA, B.HARD_OBJECTS[o]["model"])
    # The long section's sequences (their draws are made by run, as links) or the slow section's
    # (precision; run --mismatch tracks them with the mesh off).
    variant = (("long", B.LONG_CONDITIONS, B.LONG_FRAMES) if a.long else
               ("slow", B.SLOW_CONDITIONS, B.HARD_FRAMES) if a.slow else None)
    if variant:
        name, conditions, frames = variant
        keys = [(o, c) for o in B.HARD_OBJECTS for c in conditions]
        with concurrent.futures.ThreadPoolExecutor(os.cpu_count() or 1) as ex:
            list(ex.map(lambda k: B.variant_sequence(DATA, name, conditions, k[0], k[1], frames), keys))
        return

    def one(key):
        s, o, c = key
        source = B.hard_sequence(DATA, o, c, B.HARD_FRAMES, s)
        for d in range(1, B.NOISE_DRAWS):
            B.perturbed_sequence(DATA, source, s, o, c, d)
    keys = [(s, o, c) for s in B.HARD_SETS for o in B.HARD_OBJECTS for c in B.HARD_CONDITIONS]
    with concurrent.futures.ThreadPoolExecutor(os.cpu_count() or 1) as ex:
        list(ex.map(one, keys))


def run(a):
    # benchmark.py's Runner with this binary: its runs under DATA/dev/LABEL/.
    # --camera-rate: as a live camera (track_sequence --camera-rate; timing-dependent: use
    # --jobs 1 on an otherwise idle machine, and compare against a base run the same way).
    runner = B.Runner(ROOT, DATA, track_sequence=[a.binary] + (
        ["--camera-rate", "%g" % a.camera_rate] if a.camera_rate > 0 else []))
    params = dict(kv.split("=", 1) for kv in a.params)
    # --long: the long section's sequences (300 frames; `generate --long` renders them) instead of
    # the hard sets: what a wrong hold costs, from the same perturbed initial poses.
    # --slow: the slow section's (precision on slow footage; with --mismatch, the mesh 3 % off):
    # the rows carry the median rotation and translation errors as well.
    sets = ["long"] if a.long else ["slow"] if a.slow else a.sets.split(",")
    conditions = a.conditions or ",".join(B.LONG_CONDITIONS if a.long else B.SLOW_CONDITIONS if a.slow
                                          else B.HARD_CONDITIONS)
    jobs = [(d, s, o, c) for d in map(int, a.draws.split(",")) for s in sets
            for o in a.objects.split(",") for c in conditions.split(",")]

    # Per object: the model tracked and the one scored against (None: the same). --mismatch: the
    # mismatch section's model (3 % off the object), written once before the threads read it.
    models = {}
    for o in a.objects.split(","):
        true_model = os.path.join(DATA, "models", B.HARD_OBJECTS[o]["model"] + ".obj")
        models[o] = ((B.mismatched_model(DATA, B.HARD_OBJECTS[o]["model"]), true_model) if a.mismatch
                     else (true_model, None))

    def one(job):
        d, s, o, c = job
        source = os.path.join(DATA, s, o, c)
        folder = B.perturbed_sequence(DATA, source, s, o, c, d)
        r = runner.track("dev", (a.label, a.preset, params), "%s/%s/%s/d%d" % (s, o, c, d), folder,
                         models[o][0], score_model=models[o][1], hypotheses=a.hypotheses)
        if not r:  # Runner logged the failure
            return None
        B.score_visible(r, source)
        errors = B.pose_errors(B.read_poses(r["poses_file"]), B.read_poses(os.path.join(source, "pose.txt")))
        return dict(draw=d, set=s, object=o, condition=c, auc=r["auc"], scored_frames=r["scored_frames"],
                    diameter_m=r["diameter_m"], errors=r["errors"], states=r["states"],
                    visible_errors=r["visible_errors"], hypotheses_file=r.get("hypotheses_file"),
                    rotation_deg=B.median([e[0] for e in errors]), translation_mm=B.median([e[1] for e in errors]))
    with concurrent.futures.ThreadPoolExecutor(a.jobs) as ex:
        rows = [r for r in ex.map(one, jobs) if r]
    json.dump(dict(label=a.label, binary=a.binary, preset=a.preset, params=a.params, mismatch=a.mismatch,
                   long=a.long, slow=a.slow, rows=rows),
              open(os.path.join(DEV, a.label + ".json"), "w"))
    for d in sorted({r["draw"] for r in rows}):
        print("draw %d: AUC %.2f" % (d, B.weighted_auc([r for r in rows if r["draw"] == d])))
    print("all: AUC %.2f, re-acquired right within 10 frames of being visible: %d of %d" % (
        (B.weighted_auc(rows),) + reacquisitions(rows)))
    print("median over the runs of each run's median error: rotation %s deg, translation %s mm" % precision(rows))
    return 0 if len(rows) == len(jobs) else 1


def precision(rows):
    """The median over `rows` of each run's median rotation (deg) and translation (mm) error,
    formatted ("-" for rows from before they were recorded)."""
    return (B.fmt(B.median([r.get("rotation_deg") for r in rows])),
            B.fmt(B.median([r.get("translation_mm") for r in rows]), 1))


def reacquisitions(rows):
    right = losses = 0
    for r in rows:
        got = B.reacquired_right_once_visible(r)
        if got:
            right, losses = right + got[0], losses + got[1]
    return right, losses


def compare(a):
    runs = {label: json.load(open(os.path.join(DEV, label + ".json"))) for label in (a.candidate, a.base)}
    if runs[a.candidate].get("mismatch", False) != runs[a.base].get("mismatch", False):
        print("%s and %s differ in --mismatch: not comparable" % (a.candidate, a.base), file=sys.stderr)
        return 1
    load = lambda label: runs[label]["rows"]
    key = lambda r: (r["set"], r["object"], r["condition"], r["draw"])
    base = {key(r): r for r in load(a.base)}
    cand = [r for r in load(a.candidate) if key(r) in base]
    if not cand:
        print("no run in common", file=sys.stderr)
        return 1
    ref = [base[key(r)] for r in cand]
    draws = sorted({r["draw"] for r in cand})
    diffs = [B.weighted_auc([r for r in cand if r["draw"] == d]) - B.weighted_auc([r for r in ref if r["draw"] == d])
             for d in draws]
    mean = sum(diffs) / len(diffs)
    sd = (sum((x - mean) ** 2 for x in diffs) / max(1, len(diffs) - 1)) ** 0.5
    print("%s %.2f, %s %.2f: paired %+.2f +- %.2f (%s)" % (a.candidate, B.weighted_auc(cand), a.base,
                                                         B.weighted_auc(ref), mean, sd,
                                                         " ".join("%+.2f" % x for x in diffs)))
    print("re-acquired right: %d of %d, was %d of %d" % (reacquisitions(cand) + reacquisitions(ref)))
    print("median error (rotation deg / translation mm): %s / %s, was %s / %s" % (precision(cand) + precision(ref)))
    conditions = list(B.HARD_CONDITIONS) + [c for c in list(B.LONG_CONDITIONS) + list(B.SLOW_CONDITIONS)
                                            if c not in B.HARD_CONDITIONS]
    for c in conditions:
        sel = [r for r in cand if r["condition"] == c]
        if sel:
            print("  %-10s %.2f -> %.2f   %s / %s -> %s / %s" % (
                (c, B.weighted_auc([base[key(r)] for r in sel]), B.weighted_auc(sel)) +
                precision([base[key(r)] for r in sel]) + precision(sel)))
    changed = sorted((r["auc"] - base[key(r)]["auc"], key(r)) for r in cand if abs(r["auc"] - base[key(r)]["auc"]) > 0.05)
    print("runs changed: %d (%d up, %d down)" % (len(changed), sum(x > 0 for x, _ in changed),
                                                 sum(x < 0 for x, _ in changed)))
    for x, k in changed[:5] + changed[-5:] if len(changed) > 10 else changed:
        print("  %+.2f %s/%s/%s draw %d" % ((x,) + k))
    return 0


def reach(a):
    """How far the re-acquisition's hypotheses reach: over the frames that re-acquire (the state
    is lost) with the object visible (the benchmark's HARD_MIN_VISIBLE), the frames where a
    refined hypothesis is right (error < WRONG_POSE_DIAMETERS, the "re-acquired right" measure),
    where the search chose a right one, where one is at the right place (centre within that
    share of the diameter), where the chosen one is, and how far the ones at the right place
    are turned. The choice can do no better than the first count."""
    rows = json.load(open(os.path.join(DEV, a.label + ".json")))["rows"]
    if not any(r.get("hypotheses_file") for r in rows):
        print("%s: no hypotheses recorded (run it with --hypotheses)" % a.label, file=sys.stderr)
        return 1
    limit = B.WRONG_POSE_DIAMETERS
    counts = {}
    turns = []
    for r in rows:
        path = r.get("hypotheses_file")
        if not path or not os.path.exists(path):
            continue
        frames = {}
        with open(path) as f:
            header = f.readline().strip().split(",")
            for line in f:
                h = dict(zip(header, line.strip().split(",")))
                i = int(h["frame"])
                if h["reacquiring"] != "1" or not h["error_diameters"] or \
                        i >= len(r["visible_errors"]) or r["visible_errors"][i] is None:
                    continue
                frames.setdefault(i, []).append(h)
        cell = counts.setdefault(r["condition"], [0] * 5)
        for hs in frames.values():
            right = [float(h["error_diameters"]) < limit for h in hs]
            placed = [float(h["centre_diameters"]) < limit for h in hs]
            chosen = [h["chosen"] == "1" for h in hs]
            cell[0] += 1
            cell[1] += any(right)
            cell[2] += any(x and c for x, c in zip(right, chosen))
            cell[3] += any(placed)
            cell[4] += any(x and c for x, c in zip(placed, chosen))
            turns += [float(h["rotation_deg"]) for h, x in zip(hs, placed) if x]
    print("%s: frames that re-acquire with the object visible; of them, a right hypothesis "
          "(error < %.2f diameters) / chosen right / one at the right place (centre < %.2f) / "
          "chosen there" % (a.label, limit, limit))
    total = [0] * 5
    for c in B.HARD_CONDITIONS:
        if c in counts:
            print("  %-10s %5d  right %4d  chosen right %4d  placed %4d  chosen placed %4d" % ((c,) + tuple(counts[c])))
            total = [t + x for t, x in zip(total, counts[c])]
    print("  %-10s %5d  right %4d  chosen right %4d  placed %4d  chosen placed %4d" % (("all",) + tuple(total)))
    if turns:
        turns.sort()
        print("  turn of the hypotheses at the right place: median %.1f deg, quartiles %.1f-%.1f" % (
            turns[len(turns) // 2], turns[len(turns) // 4], turns[3 * len(turns) // 4]))
    return 0


def truth(a):
    """Does the refinement's objective hold the truth? Every frame's true pose refined as a
    re-acquisition hypothesis is (track_sequence --truth-refinement: contour only, no keypoints,
    no shift search), on the sets' unperturbed sequences, over the frames with at least half the
    object visible: how far the refinement moves it, per condition and per object. A pose that
    leaves the truth where the objective is flat or biased cannot be held by the refinement alone
    (the keypoints must), and a hypothesis that starts there is not refined to it."""
    import subprocess
    import tempfile
    import statistics
    cells = {}
    with tempfile.TemporaryDirectory() as tmp:
        for s in a.sets.split(","):
            for o in a.objects.split(","):
                model = os.path.join(DATA, "models", B.HARD_OBJECTS[o]["model"] + ".obj")
                for c in a.conditions.split(","):
                    folder = os.path.join(DATA, s, o, c)
                    out = os.path.join(tmp, "%s_%s_%s.csv" % (s, o, c))
                    subprocess.run([a.binary, "--sequence", folder, "--model", model, "--preset", a.preset,
                                    "--truth-refinement", out, "--quiet"], check=True,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                    visible = B.read_visible(folder)
                    with open(out) as f:
                        header = f.readline().strip().split(",")
                        for line in f:
                            h = dict(zip(header, line.strip().split(",")))
                            i = int(h["frame"])
                            if i >= len(visible) or visible[i] < 0.5:
                                continue
                            gain = float(h["energy_refined"]) / float(h["energy_truth"]) if float(h["energy_truth"]) > 0 else 1.0
                            row = (abs(float(h["depth_mm"])), float(h["rotation_deg"]), float(h["error_diameters"]), gain)
                            for key in (c, o, "all"):
                                cells.setdefault(key, []).append(row)
    print("the true pose refined (contour only), frames with >= half the object visible: median |depth| mm, "
          "median / 90th-percentile rotation deg, share turned > 5 deg, share still right (error < %.2f "
          "diameters), median energy gain" % B.WRONG_POSE_DIAMETERS)
    for key in a.conditions.split(",") + a.objects.split(",") + ["all"]:
        rows = cells.get(key)
        if not rows:
            continue
        rot = sorted(r[1] for r in rows)
        print("  %-10s %5d  |depth| %5.1f  rotation %5.2f / %5.1f  > 5 deg %3.0f %%  right %3.0f %%  gain %.3f" % (
            key, len(rows), statistics.median(r[0] for r in rows), statistics.median(rot), rot[int(0.9 * (len(rot) - 1))],
            100.0 * sum(x > 5.0 for x in rot) / len(rot),
            100.0 * sum(r[2] < B.WRONG_POSE_DIAMETERS for r in rows) / len(rows),
            statistics.median(r[3] for r in rows)))
    return 0


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    g = sub.add_parser("generate")
    g.add_argument("--long", action="store_true", help="render the long section's sequences")
    g.add_argument("--slow", action="store_true", help="render the slow section's sequences")
    r = sub.add_parser("run")
    r.add_argument("label")
    r.add_argument("--binary", default=os.path.join(ROOT, "build", "ws", "devel", "lib", "klt_contour_tracker",
                                                    "track_sequence"))
    r.add_argument("--draws", default=",".join(str(d) for d in range(B.NOISE_DRAWS)))
    r.add_argument("--sets", default=",".join(B.HARD_SETS))
    r.add_argument("--objects", default=",".join(B.HARD_OBJECTS))
    r.add_argument("--conditions", help="default: the set's all")
    r.add_argument("--preset", default="realtime")
    r.add_argument("--long", action="store_true",
                   help="the long section's sequences (set long, its conditions) instead of --sets")
    r.add_argument("--slow", action="store_true",
                   help="the slow section's sequences (set slow, its conditions): precision; with --mismatch, "
                        "the mesh 3 %% off")
    r.add_argument("--mismatch", action="store_true",
                   help="track with the model 3 %% off the object (the mismatch section's), scored against the true one")
    r.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    r.add_argument("--camera-rate", type=float, default=0.0, metavar="HZ",
                   help="replay as a live camera at HZ (frames dropped while busy); 0: every frame")
    r.add_argument("--param", action="append", default=[], dest="params", metavar="NAME=VALUE",
                   help="a track_sequence --param override (repeat for several)")
    r.add_argument("--hypotheses", action="store_true",
                   help="also record the colour searches' refined hypotheses (for reach)")
    c = sub.add_parser("compare")
    c.add_argument("candidate")
    c.add_argument("base")
    h = sub.add_parser("reach")
    h.add_argument("label")
    t = sub.add_parser("truth")
    t.add_argument("--binary", default=r.get_default("binary"))
    t.add_argument("--sets", default=",".join(B.HARD_SETS))
    t.add_argument("--objects", default=",".join(B.HARD_OBJECTS))
    t.add_argument("--conditions", default=",".join(B.HARD_CONDITIONS))
    t.add_argument("--preset", default="realtime")
    a = p.parse_args()
    return {"generate": generate, "run": run, "compare": compare, "reach": reach, "truth": truth}[a.command](a) or 0


if __name__ == "__main__":
    sys.exit(main())
