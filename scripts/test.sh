#!/usr/bin/env bash
# Runs every test: installs what is missing, builds, then ctest (gtest units + rostests).
# Ends with ctest's summary line and exits non-zero on any failure.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
"$KCT_ROOT/scripts/setup.sh"
"$KCT_ROOT/scripts/build.sh" --tests
source_ws
cd "$KCT_WS/build"
log "test: ctest"
ctest --output-on-failure --timeout 600
