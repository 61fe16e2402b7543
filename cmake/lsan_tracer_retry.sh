#!/usr/bin/env bash
# lsan_tracer_retry.sh COMMAND [ARGS...]: runs COMMAND (a sanitized test) and runs it once more
# only when it failed solely because LeakSanitizer's own stop-the-world tracer crashed at exit.
#
# That crash ("Tracer caught signal 11" + "LeakSanitizer has encountered a fatal error", no leak
# report) is a known flake of the sanitizer runtime, not of the code under test: it hits roughly
# one process exit in a few hundred (google/sanitizers#1353), and the project's CI saw it once
# (core_only_test_tracking_session, 2026-12-04: 14 of 14 tests passed, then the tracer died).
# Everything else keeps its verdict and is never rerun: any sanitizer report (ERROR: / SUMMARY:),
# a gtest run without its PASSED line or with a FAILED line, only half of the signature, an
# ordinary non-zero exit, a crash, and a second tracer crash.
set -u
[ $# -ge 1 ] || { echo "usage: lsan_tracer_retry.sh COMMAND [ARGS...]" >&2; exit 2; }
log="$(mktemp)"
trap 'rm -f "$log"' EXIT

run() {
  # The output goes to ctest as it comes, and to $log for the verdict.
  "$@" 2>&1 | tee "$log"
  return "${PIPESTATUS[0]}"
}

tracer_flake_only() {
  grep -q "Tracer caught signal" "$log" &&
    grep -q "LeakSanitizer has encountered a fatal error" "$log" &&
    ! grep -q "ERROR: \(Address\|Leak\|UndefinedBehavior\)Sanitizer" "$log" &&
    ! grep -q "SUMMARY: \(Address\|Leak\|UndefinedBehavior\)Sanitizer" "$log" &&
    ! grep -q "runtime error:" "$log" &&
    ! grep -q "^\[  FAILED  \]" "$log" &&
    # A gtest binary must have said that it passed; other commands have no such line.
    { ! grep -q "^\[==========\]" "$log" || grep -q "^\[  PASSED  \]" "$log"; }
}

run "$@"
status=$?
if [ $status -ne 0 ] && tracer_flake_only; then
  echo "lsan_tracer_retry: the command passed but LeakSanitizer's tracer crashed at exit" \
       "(a sanitizer-runtime flake, no leak reported): running it once more" >&2
  run "$@"
  status=$?
fi
exit $status
