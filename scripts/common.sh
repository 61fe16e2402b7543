#!/usr/bin/env bash
# Shared environment for the scripts: Debian's ROS 1 lives under /usr, nothing to source.
# A pyenv python3 may shadow /usr/bin/python3 (no catkin_pkg there), so /usr/bin goes first.
set -euo pipefail
KCT_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
KCT_WS="${KCT_WS:-$KCT_ROOT/build/ws}"
KCT_DATA="${KCT_DATA:-$KCT_ROOT/data}"
export PATH="/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
export ROS_HOSTNAME="${ROS_HOSTNAME:-localhost}"
export ROS_HOME="${ROS_HOME:-$KCT_ROOT/build/ros_home}"
mkdir -p "$ROS_HOME"
log() { echo "[$(date +%H:%M:%S)] $*" >&2; }
source_ws() {
  # setup.bash reads unset variables; relax -u while sourcing it.
  set +u; source "$KCT_WS/devel/setup.bash"; set -u
}
