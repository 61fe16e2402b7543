#!/usr/bin/env bash
# Demo: installs and builds, renders a 150-frame 640x480 sequence of the demo crate (free
# motion) into data/demo/demo.bag if absent, tracks it with the nodelet through
# `roslaunch klt_contour_tracker track_bag.launch` (the bag is played at a rate the tracker can
# follow: rosbag play pauses on the tracker's ~status), records the output and scores it against
# the ground truth with evaluate_bag.
#   KCT_DEMO_PRESET=realtime|paper|klt_only (default realtime)   KCT_DEMO_FRAMES (default 150)
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
PRESET="${KCT_DEMO_PRESET:-realtime}"
FRAMES="${KCT_DEMO_FRAMES:-150}"
DEMO_DIR="$KCT_DATA/demo"
BAG="$DEMO_DIR/demo.bag"
TRACKED="$DEMO_DIR/tracked_$PRESET.bag"

"$KCT_ROOT/scripts/setup.sh"
"$KCT_ROOT/scripts/build.sh"
source_ws
mkdir -p "$DEMO_DIR"

if [ ! -f "$BAG" ]; then
  log "demo: rendering $FRAMES frames into $BAG (sequence folder $DEMO_DIR/sequence)"
  rosrun klt_contour_tracker generate_sequence --model "$KCT_ROOT/models/demo_crate.obj" \
    --output-dir "$DEMO_DIR/sequence" --bag "$BAG.tmp" --frames "$FRAMES" \
    --width 640 --height 480 --motion free --seed 1
  mv "$BAG.tmp" "$BAG"
else
  log "demo: using the existing $BAG (delete it to render again)"
fi

# The tracker starts from the first ground-truth pose (object_to_camera, camera optical frame).
rosrun klt_contour_tracker first_pose "$BAG" --output "$DEMO_DIR/initial_pose.yaml"
log "demo: initial pose from the bag's first /ground_truth/pose:"
grep -v '^#' "$DEMO_DIR/initial_pose.yaml" >&2

log "demo: tracking with preset '$PRESET' (roslaunch klt_contour_tracker track_bag.launch)"
rm -f "$TRACKED" "$TRACKED.active"
roslaunch klt_contour_tracker track_bag.launch bag:="$BAG" preset:="$PRESET" \
  initial_pose_file:="$DEMO_DIR/initial_pose.yaml" record_output:="$TRACKED" \
  2>&1 | tee "$DEMO_DIR/launch_$PRESET.log" | grep -vE '^  [a-z_/]+: ' || true
if [ ! -f "$TRACKED" ]; then
  echo "demo: the tracker output $TRACKED was not written (log: $DEMO_DIR/launch_$PRESET.log)" >&2
  exit 1
fi

log "demo: evaluation"
rosrun klt_contour_tracker evaluate_bag "$TRACKED" --ground-truth "$BAG"
