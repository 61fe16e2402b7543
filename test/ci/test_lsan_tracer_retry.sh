#!/usr/bin/env bash
# Tests cmake/lsan_tracer_retry.sh with fake commands: it reruns exactly once, and only a run
# that failed because LeakSanitizer's tracer crashed after everything passed.
set -u
retry="$(dirname "${BASH_SOURCE[0]}")/../../cmake/lsan_tracer_retry.sh"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
failures=0

# fake OUTPUT_FIRST STATUS_FIRST OUTPUT_LATER STATUS_LATER: a command whose first run prints
# OUTPUT_FIRST and exits STATUS_FIRST, every later run OUTPUT_LATER / STATUS_LATER; it counts its
# runs in $work/runs.
fake() {
  cat > "$work/fake.sh" <<EOF
#!/usr/bin/env bash
n=\$(( \$(cat "$work/runs" 2>/dev/null || echo 0) + 1 ))
echo \$n > "$work/runs"
if [ \$n -eq 1 ]; then printf '%b' "$1"; exit $2; else printf '%b' "$3"; exit $4; fi
EOF
  chmod +x "$work/fake.sh"
  rm -f "$work/runs"
}

# expect NAME WANTED_STATUS WANTED_RUNS
expect() {
  "$retry" "$work/fake.sh" > "$work/out" 2>&1
  local status=$? runs
  runs=$(cat "$work/runs")
  if [ $status -ne "$2" ] || [ "$runs" -ne "$3" ]; then
    echo "FAILED: $1: exit $status after $runs run(s), wanted exit $2 after $3"
    sed 's/^/  | /' "$work/out"
    failures=$((failures + 1))
  else
    echo "ok: $1"
  fi
}

passed='[==========] 14 tests ran.\n[  PASSED  ] 14 tests.\n'
failed='[==========] 14 tests ran.\n[  PASSED  ] 13 tests.\n[  FAILED  ] 1 test.\n'
tracer='Tracer caught signal 11: addr=0x0 pc=0x1 sp=0x2\n==1==LeakSanitizer has encountered a fatal error.\n'
leak='==1==ERROR: LeakSanitizer: detected memory leaks\nSUMMARY: AddressSanitizer: 64 byte(s) leaked\n'

fake "$passed" 0 "$passed" 0
expect "a pass is run once" 0 1
fake "$passed$tracer" 1 "$passed" 0
expect "the tracer's crash after a pass is run again and passes" 0 2
fake "$passed$tracer" 1 "$passed$tracer" 1
expect "a second tracer crash fails" 1 2
fake "$failed$tracer" 1 "$passed" 0
expect "a failed test is not rerun, tracer or not" 1 1
fake "$passed$leak$tracer" 1 "$passed" 0
expect "a leak report is not rerun" 1 1
fake "$passed" 1 "$passed" 0
expect "an ordinary non-zero exit is not rerun" 1 1
fake "${passed}Tracer caught signal 11\n" 1 "$passed" 0
expect "half of the signature is not rerun" 1 1
fake "[==========] 14 tests ran.\n$tracer" 1 "$passed" 0
expect "a gtest run without its PASSED line is not rerun" 1 1
fake "frames 6\n$tracer" 1 "frames 6\n" 0
expect "a non-gtest command's tracer crash is run again" 0 2
fake "x.cpp:1:2: runtime error: signed integer overflow\n$tracer" 1 "" 0
expect "an UndefinedBehaviorSanitizer report is not rerun" 1 1

[ $failures -eq 0 ] && echo "all passed" || echo "$failures failed"
exit $((failures != 0))
