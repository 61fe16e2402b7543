#!/usr/bin/env bash
# Builds the package (and its tests) in a catkin workspace under build/ws (git-ignored).
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
# The workspace's package folder links every top-level entry of the repository except build/
# and data/: a link to the repository root itself would be a loop (build/ws/src/pkg/build/ws/...)
# that roslaunch's launch-file search follows forever.
pkg_dir="$KCT_WS/src/klt_contour_tracker"
[ -L "$pkg_dir" ] && rm "$pkg_dir"
mkdir -p "$pkg_dir"
find "$pkg_dir" -maxdepth 1 -type l -delete
for entry in "$KCT_ROOT"/* "$KCT_ROOT"/.clang-format; do
  [ -e "$entry" ] || continue
  name="$(basename "$entry")"
  case "$name" in build|data) continue ;; esac
  ln -s "$entry" "$pkg_dir/$name"
done
cd "$KCT_WS"
jobs="${KCT_JOBS:-$(nproc)}"
log "build: catkin_make (Release, -j$jobs)"
catkin_make -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3 -j"$jobs" >"$KCT_WS/build.log" 2>&1 \
  || { tail -n 80 "$KCT_WS/build.log"; echo "build: FAILED (full log: $KCT_WS/build.log)" >&2; exit 1; }
if [ "${1:-}" = "--tests" ]; then
  # Re-configure once the devel space exists (catkin caches an empty PYTHONPATH on the first
  # configure), then build the test binaries, which the default target leaves out.
  log "build: test binaries"
  catkin_make --force-cmake -DCMAKE_BUILD_TYPE=Release -DPYTHON_EXECUTABLE=/usr/bin/python3 -j"$jobs" tests \
    >>"$KCT_WS/build.log" 2>&1 \
    || { tail -n 80 "$KCT_WS/build.log"; echo "build: FAILED (full log: $KCT_WS/build.log)" >&2; exit 1; }
fi
if grep -q "warning:" "$KCT_WS/build.log"; then
  echo "build: compiler warnings:" >&2; grep -A3 "warning:" "$KCT_WS/build.log" | head -n 40 >&2
fi
log "build: done"
