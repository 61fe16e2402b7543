#!/usr/bin/env bash
# OPT-style benchmark: installs and builds (like demo.sh), generates the missing models and
# sequences under data/benchmark (cached, deterministic), tracks them with each preset and
# writes docs/benchmarks.md plus the success-curve PNGs in docs/benchmarks/.
#   scripts/benchmark.sh [--quick] [--preset NAME ...] [--objects can,chest,...] [--frames N]
#   --quick: can and chest, 11 sequences of 30 frames each (about 4 min on 2 cores)
#   full run: can, chest, rock, bike, can_1080p x 23 sequences (60/60/60/12/40 frames):
#             about 45 min on 2 idle cores; --frames N sets every object's sequence length,
#             --track-frames N tracks only the first N frames (keeps the cached sequences)
#   default presets: realtime, paper and klt_only (repeat --preset to choose)
COMMAND="${KCT_WS:+KCT_WS=$KCT_WS }scripts/benchmark.sh $*"
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
ARGS=()
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) ARGS+=(--quick); shift ;;
    --preset) [ $# -ge 2 ] || { echo "benchmark: --preset needs a name" >&2; exit 2; }
              ARGS+=(--preset "$2"); shift 2 ;;
    --objects) [ $# -ge 2 ] || { echo "benchmark: --objects needs a list" >&2; exit 2; }
               ARGS+=(--objects "$2"); shift 2 ;;
    --frames) [ $# -ge 2 ] || { echo "benchmark: --frames needs a number" >&2; exit 2; }
              ARGS+=(--frames "$2"); shift 2 ;;
    --track-frames) [ $# -ge 2 ] || { echo "benchmark: --track-frames needs a number" >&2; exit 2; }
              ARGS+=(--track-frames "$2"); shift 2 ;;
    -h|--help) sed -n '2,10p' "$0"; exit 0 ;;
    *) echo "benchmark: unknown argument $1" >&2; exit 2 ;;
  esac
done
"$KCT_ROOT/scripts/setup.sh"
"$KCT_ROOT/scripts/build.sh"
source_ws
export KCT_DATA
/usr/bin/python3 "$KCT_ROOT/scripts/benchmark.py" --repo "$KCT_ROOT" --command "$COMMAND" ${ARGS[@]+"${ARGS[@]}"}
