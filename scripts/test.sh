#!/usr/bin/env bash
# Runs every test: installs what is missing, builds, then ctest (gtest units + rostests), and
# the guards of issue 8, plain CMake builds of the core without catkin (cmake/core_only.cmake):
# the core, its gtests and a short track_sequence run with AddressSanitizer and
# UndefinedBehaviorSanitizer (gcc, $KCT_WS/sanitize), and the libFuzzer targets of test/fuzz on
# their seed corpora and regression inputs (clang, $KCT_WS/fuzz). The guards' tests are part of
# the one ctest run below (its summary line counts them). KCT_GUARDS=0 skips them.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
"$KCT_ROOT/scripts/setup.sh"
"$KCT_ROOT/scripts/build.sh" --tests
source_ws
jobs="${KCT_JOBS:-$(nproc)}"
# guard_build DIR COMPILER CMAKE_ARGS...: configures and builds cmake/core_only.cmake in DIR.
guard_build() {
  local dir="$1" cc="$2" cxx="$3"; shift 3
  mkdir -p "$dir"
  (cd "$dir" && CC="$cc" CXX="$cxx" cmake -DKCT_CORE_ONLY=ON -DKCT_SANITIZE=ON \
     -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@" "$KCT_ROOT" >"$dir/build.log" 2>&1 &&
   make -j"$jobs" >>"$dir/build.log" 2>&1) \
    || { tail -n 60 "$dir/build.log"; echo "test: guard build FAILED (log: $dir/build.log)" >&2; exit 1; }
}
if [ "${KCT_GUARDS:-1}" != "0" ]; then
  # gcc for the gtests: the same floating point as the Release build, so that the accuracy
  # assertions hold (clang's differs enough to move chaotic optimizations, e.g. basin hopping).
  log "test: sanitizer build (gcc, ASan + UBSan, core + gtests + track_sequence, no catkin)"
  guard_build "$KCT_WS/sanitize" gcc g++ \
    -DKCT_SEQUENCE_DIR="$KCT_WS/devel/share/klt_contour_tracker/test_data/small"
  log "test: fuzz build (clang, libFuzzer + ASan + UBSan)"
  guard_build "$KCT_WS/fuzz" clang clang++ -DKCT_FUZZ=ON -DKCT_CORE_TESTS=OFF
else
  rm -f "$KCT_WS/sanitize/CTestTestfile.cmake" "$KCT_WS/fuzz/CTestTestfile.cmake"  # not this run
fi
cd "$KCT_WS/build"
log "test: ctest"
# Sanitizer reports end the process with an error (UBSan: -fno-sanitize-recover=all).
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
ctest --output-on-failure --timeout 600
