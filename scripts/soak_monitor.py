#!/usr/bin/env python3
"""Soak monitor (scripts/soak.sh): counts the images sent (their camera_info), the tracker's
~status and ~pose, bag loop restarts (the image stamp jumps back) and whether tracking resumes
after each, samples the manager's RSS, stops after --frames images and prints a summary
(also written as JSON with --json)."""
import argparse
import json
import os
import signal
import sys
import threading
import time

import rospy
from geometry_msgs.msg import PoseStamped
from sensor_msgs.msg import CameraInfo

from klt_contour_tracker.msg import TrackerStatus


def rss_kb(pid):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


class Monitor:
    def __init__(self, args):
        self.args = args
        self.lock = threading.Lock()
        self.images = 0
        self.statuses = 0
        self.poses = 0
        self.invalid = 0
        self.dropped_total = 0
        self.last_image_stamp = None
        self.restarts = 0           # image stamp went back (bag loop)
        self.restarts_tracked = 0   # ... and a pose was published after it, before the next one
        self.status_stamps_back = 0
        self.tracked_since_status_restart = True
        self.last_status_stamp = None
        self.frame_ms = []
        self.rss = []               # (seconds since start, kB)
        self.start = time.time()
        self.done = threading.Event()

    def on_image(self, msg):
        with self.lock:
            if self.done.is_set():
                return  # sent after the player was told to stop: not part of the run
            self.images += 1
            if self.last_image_stamp is not None and msg.header.stamp < self.last_image_stamp:
                self.restarts += 1
            self.last_image_stamp = msg.header.stamp
            if self.images >= self.args.frames:
                self.done.set()

    def on_status(self, msg):
        with self.lock:
            self.statuses += 1
            self.dropped_total = max(self.dropped_total, msg.dropped_frames_total)
            if msg.state == "invalid_input":
                self.invalid += 1
            self.frame_ms.append(msg.frame_time_ms)
            # The status stream's own jump back marks the restart on the tracker's side; the
            # first published pose after it counts the restart as tracked again.
            if self.last_status_stamp is not None and msg.header.stamp < self.last_status_stamp:
                self.status_stamps_back += 1
                self.tracked_since_status_restart = False
            if msg.pose_published and self.status_stamps_back > 0 and \
                    not self.tracked_since_status_restart:
                self.restarts_tracked += 1
                self.tracked_since_status_restart = True
            self.last_status_stamp = msg.header.stamp

    def on_pose(self, _msg):
        with self.lock:
            self.poses += 1

    def sample_rss(self):
        while not self.done.is_set() and not rospy.is_shutdown():
            try:
                self.rss.append((time.time() - self.start, rss_kb(self.args.pid)))
            except (OSError, ValueError):
                print("soak: the manager (pid %d) is gone" % self.args.pid, file=sys.stderr)
                self.done.set()
                return
            self.done.wait(self.args.rss_period)

    def summary(self):
        with self.lock:
            elapsed = time.time() - self.start
            after_2min = [kb for t, kb in self.rss if t >= 120.0]
            base = after_2min[0] if after_2min else (self.rss[0][1] if self.rss else 0)
            end = self.rss[-1][1] if self.rss else 0
            ms = sorted(self.frame_ms)
            # A restart in the last seconds (no status of it yet) is not counted against tracking.
            restarts = min(self.restarts, self.status_stamps_back -
                           (0 if self.tracked_since_status_restart else 1))
            return {
                "preset": self.args.preset,
                "rate_hz": self.args.rate,
                "duration_s": round(elapsed, 1),
                "images_sent": self.images,
                "statuses": self.statuses,
                "status_ratio": round(self.statuses / max(1, self.images), 4),
                "poses": self.poses,
                "invalid_input_statuses": self.invalid,
                "dropped_before_tracker_reported": self.dropped_total,
                "loop_restarts": restarts,
                "loop_restarts_tracked_again": self.restarts_tracked,
                "frame_time_ms_median": round(ms[len(ms) // 2], 2) if ms else None,
                "frame_time_ms_p99": round(ms[int(0.99 * (len(ms) - 1))], 2) if ms else None,
                "rss_kb_first": self.rss[0][1] if self.rss else None,
                "rss_kb_at_2min": base,
                "rss_kb_end": end,
                "rss_growth_from_2min_pct": round(100.0 * (end - base) / base, 2) if base else None,
                "rss_samples": self.rss,
            }


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--frames", type=int, required=True)
    parser.add_argument("--pid", type=int, required=True, help="pid of the nodelet manager")
    parser.add_argument("--node", default="/tracker")
    parser.add_argument("--camera-info", default="/camera/camera_info",
                        help="counted as the images sent (one per image; far cheaper to receive)")
    parser.add_argument("--preset", default="")
    parser.add_argument("--rate", type=float, default=0.0)
    parser.add_argument("--rss-period", type=float, default=10.0)
    parser.add_argument("--json", default="")
    parser.add_argument("--player-pid-file", default="",
                        help="file with the pid of the bag player, stopped after --frames images")
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node("soak_monitor", disable_signals=True)
    monitor = Monitor(args)
    rospy.Subscriber(args.camera_info, CameraInfo, monitor.on_image, queue_size=1000)
    rospy.Subscriber(args.node + "/status", TrackerStatus, monitor.on_status, queue_size=1000)
    rospy.Subscriber(args.node + "/pose", PoseStamped, monitor.on_pose, queue_size=1000)
    sampler = threading.Thread(target=monitor.sample_rss, daemon=True)
    sampler.start()
    last_print = time.time()
    while not monitor.done.wait(1.0):
        if time.time() - last_print >= 60.0:
            s = monitor.summary()
            print("soak: %6.0f s  images %d  statuses %d  poses %d  restarts %d/%d  rss %d kB" % (
                s["duration_s"], s["images_sent"], s["statuses"], s["poses"],
                s["loop_restarts_tracked_again"], s["loop_restarts"], s["rss_kb_end"]), flush=True)
            last_print = time.time()
    if args.player_pid_file:
        try:
            with open(args.player_pid_file) as f:
                os.kill(int(f.read().strip()), signal.SIGINT)
        except (OSError, ValueError) as e:
            print("soak: could not stop the player: %s" % e, file=sys.stderr)
    time.sleep(3.0)  # the last frames' statuses
    s = monitor.summary()
    if args.json:
        with open(args.json, "w") as f:
            json.dump(s, f, indent=1)
    s.pop("rss_samples")
    print(json.dumps(s, indent=1))
    ok = (s["status_ratio"] >= 0.99 and s["loop_restarts_tracked_again"] >= s["loop_restarts"]
          and (s["rss_growth_from_2min_pct"] is None or s["rss_growth_from_2min_pct"] < 5.0))
    print("soak: %s (>= 99%% statuses, every loop restart tracked again, RSS growth < 5%% "
          "from minute 2)" % ("PASS" if ok else "FAIL"), flush=True)
    rospy.signal_shutdown("done")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
