#!/usr/bin/env bash
# Benchmark: installs and builds (like demo.sh), generates the missing models and sequences
# under data/benchmark (cached, deterministic), tracks them with each configuration and writes
# docs/benchmarks.md (+ docs/benchmarks/<section>.md and the success-curve PNGs).
#   scripts/benchmark.sh [--section hard|hard2|mismatch|camera|photo|noise|real|opt ...] [--quick] [--preset NAME ...]
#                        [--variant LABEL:PRESET:param=value,...] [--hard-frames N] [--reuse LABEL]
#                        [--objects can,chest,...] [--frames N] [--track-frames N]
#   sections (default: all): hard (hand-held, clutter, occlusion, leaving the image, lighting,
#     sensor effects; 4 objects x 6 conditions x 80 frames), hard2 (the same with other seeds and
#     backgrounds: a change is judged on both), mismatch (the hard frames tracked with each model
#     stretched 3 % and scored against the true one: a biased contour, as on real video), camera
#     (the hard set's frames as a live 30 Hz camera: a frame a newer one replaced while the tracker
#     was busy is dropped, as the nodelet's queue drops it; realtime, paper, klt_only), photo (4 objects x 3 conditions of hard
#     trajectories path-traced by Blender's Cycles; rendering takes ~1 h the first time), noise (realtime, klt_only, paper (first 40 frames) and each --variant on
#     both hard sets from 5 slightly perturbed initial poses: how much of a difference is
#     chance), real (ViSP's sequences from
#     visp-images-data), opt (OPT-style groups; --objects/--frames/--track-frames apply to it)
#   --quick: part of each section; run times are in docs/benchmarks.md
#   default configurations: the presets realtime, paper and klt_only that exist, plus the
#     ABLATIONS listed in scripts/benchmark.py; --preset chooses presets (repeatable),
#     --variant adds a preset with parameter overrides (repeatable); --reuse LABEL takes that
#     configuration's results from the previous run instead of tracking again
COMMAND="${KCT_WS:+KCT_WS=$KCT_WS }scripts/benchmark.sh $*"
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
ARGS=()
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) ARGS+=(--quick); shift ;;
    --preset) [ $# -ge 2 ] || { echo "benchmark: --preset needs a name" >&2; exit 2; }
              ARGS+=(--preset "$2"); shift 2 ;;
    --section) [ $# -ge 2 ] || { echo "benchmark: --section needs hard, hard2, mismatch, camera, photo, noise, real or opt" >&2; exit 2; }
               ARGS+=(--section "$2"); shift 2 ;;
    --variant) [ $# -ge 2 ] || { echo "benchmark: --variant needs LABEL:PRESET:param=value,..." >&2; exit 2; }
               ARGS+=(--variant "$2"); shift 2 ;;
    --reuse) [ $# -ge 2 ] || { echo "benchmark: --reuse needs a configuration label" >&2; exit 2; }
               ARGS+=(--reuse "$2"); shift 2 ;;
    --hard-frames) [ $# -ge 2 ] || { echo "benchmark: --hard-frames needs a number" >&2; exit 2; }
               ARGS+=(--hard-frames "$2"); shift 2 ;;
    --objects) [ $# -ge 2 ] || { echo "benchmark: --objects needs a list" >&2; exit 2; }
               ARGS+=(--objects "$2"); shift 2 ;;
    --frames) [ $# -ge 2 ] || { echo "benchmark: --frames needs a number" >&2; exit 2; }
              ARGS+=(--frames "$2"); shift 2 ;;
    --track-frames) [ $# -ge 2 ] || { echo "benchmark: --track-frames needs a number" >&2; exit 2; }
              ARGS+=(--track-frames "$2"); shift 2 ;;
    -h|--help) sed -n '2,22p' "$0"; exit 0 ;;
    *) echo "benchmark: unknown argument $1" >&2; exit 2 ;;
  esac
done
"$KCT_ROOT/scripts/setup.sh"
# Debian packages only the benchmark needs, so setup.sh (tests, demo) leaves them out: the real
# section's ViSP sequences and CAD models (visp-images-data, ~100 MB) and the photo section's path
# tracer (blender, ~300 MB with its libraries).
bench_package() {  # package, what needs it
  dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed" && return 0
  if [ "$(id -u)" -eq 0 ]; then
    log "benchmark: installing $1 ($2)"
    DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends -o DPkg::Lock::Timeout=600 \
      "$1" || { apt-get update && DEBIAN_FRONTEND=noninteractive apt-get install -y \
      --no-install-recommends "$1"; } || log "benchmark: $1 not installed: $2 is skipped"
  else
    log "benchmark: $1 is missing (run as root to install it): $2 is skipped"
  fi
}
bench_package visp-images-data "the real section"
bench_package blender "the photo section"
"$KCT_ROOT/scripts/build.sh"
source_ws
export KCT_DATA
/usr/bin/python3 "$KCT_ROOT/scripts/benchmark.py" --repo "$KCT_ROOT" --command "$COMMAND" ${ARGS[@]+"${ARGS[@]}"}
