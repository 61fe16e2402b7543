#!/usr/bin/env bash
# Soak test: a bag looped through the tracker nodelet in a nodelet manager for N frames with a
# preset; the manager's RSS is sampled every 10 s, statuses, poses and loop restarts are counted
# (scripts/soak_monitor.py), and a summary is printed (and written to --out as JSON).
#   scripts/soak.sh [--frames 30000] [--preset NAME] [--rate 30] [--bag BAG] [--queue-size 1]
#                   [--out FILE] [--nice 10] [--tracker-nice 0]
# --nice: niceness of the master, the bag player and the monitor; --tracker-nice: of the nodelet
# manager (the tracker). A niced tracker on a machine busy with other work measures the
# scheduler, not the tracker (nice 10 under a load of 15 on 2 cores: 1.6 frames/s).
# --rate: images per second sent (rosbag play -r rate / the bag's rate; the default bag is
# rendered at 30 Hz). --preset: empty = the nodelet's default. Without --bag a 300-frame bag of
# the demo crate is rendered once into $KCT_WS/soak/ by generate_sequence. Builds nothing: run
# scripts/build.sh first. Exits 0 when >= 99% of the images sent got a ~status, every loop
# restart was tracked again and the RSS grew < 5% from minute 2 to the end.
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
frames=30000 preset="" rate=30 bag="" queue_size=1 out="" nice_level=10 tracker_nice=0
while [ $# -gt 0 ]; do
  case "$1" in
    --frames) frames="$2"; shift 2 ;;
    --preset) preset="$2"; shift 2 ;;
    --rate) rate="$2"; shift 2 ;;
    --bag) bag="$2"; shift 2 ;;
    --queue-size) queue_size="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --nice) nice_level="$2"; shift 2 ;;
    --tracker-nice) tracker_nice="$2"; shift 2 ;;
    *) echo "soak: unknown argument $1" >&2; exit 2 ;;
  esac
done
source_ws
bin="$KCT_WS/devel/lib/klt_contour_tracker"
work="$KCT_WS/soak"
mkdir -p "$work"
bag_rate_hz=30
if [ -z "$bag" ]; then
  bag="$work/soak.bag"
  if [ ! -f "$bag" ]; then
    log "soak: rendering a 300-frame bag of the demo crate"
    "$bin/generate_sequence" --model "$KCT_ROOT/models/demo_crate.obj" --output-dir "$work/sequence" \
      --bag "$bag" --frames 300 --seed 5 >/dev/null
  fi
fi
"$bin/first_pose" "$bag" >"$work/initial_pose.yaml"
[ -n "$out" ] || out="$work/soak_summary.json"

# A private master on a free port: nothing else is disturbed and nothing disturbs the run.
port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://localhost:$port"
pids=()
cleanup() {
  for ((i=${#pids[@]}-1; i>=0; i--)); do kill "${pids[$i]}" 2>/dev/null || true; done
  wait 2>/dev/null || true
}
trap cleanup EXIT
trap "exit 130" INT TERM
nice -n "$nice_level" roscore -p "$port" >"$work/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 60); do rosparam list >/dev/null 2>&1 && break; sleep 0.5; done

rosparam load "$work/initial_pose.yaml" /tracker
rosparam set /tracker/mesh_resource "file://$KCT_ROOT/models/demo_crate.obj"
rosparam set /tracker/queue_size "$queue_size"
[ -n "$preset" ] && rosparam set /tracker/preset "$preset"
nice -n "$tracker_nice" /usr/lib/nodelet/nodelet manager __name:=soak_manager >"$work/manager.log" 2>&1 &
manager_pid=$!
pids+=($manager_pid)
sleep 2
/usr/lib/nodelet/nodelet load klt_contour_tracker/TrackerNodelet soak_manager __name:=tracker \
  image:=/camera/image_raw >"$work/load.log" 2>&1 &
pids+=($!)
sleep 5

factor=$(python3 -c "print($rate / $bag_rate_hz)")
log "soak: $frames frames at $rate Hz (preset '${preset:-default}', queue $queue_size), manager pid $manager_pid (nice $tracker_nice), load: $(cut -d' ' -f1-3 /proc/loadavg)"
nice -n "$nice_level" python3 "$KCT_ROOT/scripts/soak_monitor.py" --frames "$frames" --pid "$manager_pid" \
  --preset "${preset:-default}" --rate "$rate" --json "$out" \
  --player-pid-file "$work/player.pid" &
monitor_pid=$!
pids+=($monitor_pid)
sleep 3
nice -n "$nice_level" rosbag play -q -l -r "$factor" "$bag" >"$work/play.log" 2>&1 &
pids+=($!)
echo $! >"$work/player.pid"
status=0
wait "$monitor_pid" || status=$?
log "soak: summary in $out (manager log: $work/manager.log)"
exit "$status"
