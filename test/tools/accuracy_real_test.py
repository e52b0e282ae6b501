#!/usr/bin/python3
"""tools/accuracy_real.sh (make accuracy-real) end to end on a simulated drive laid out as
tools/xviz_to_kitti.py lays out a KITTI-raw one: HDL-64E sweeps timed by their azimuth, as KITTI's .bin
scans, and OXTS's speed and yaw rate beside the ground truth (oxts.txt). The ground truth's positions
slide 0.1 m sideways a scan over scans 15-24 under an unchanged heading, as drive 0005's GPS positions
do (docs/real_drives.md): the script must find that stretch and score the segments clear of it (its
truth `clear`) at the odometry's own drift, far below its drift against the whole straying truth.

Usage: accuracy_real_test.py BUILD_DIR   (a build whose catkin devel space is BUILD_DIR/devel)"""
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

SOURCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
BUILD = None
SCANS = 50
SLIDE_FIRST, SLIDE_SCANS, SLIDE_M = 15, 10, 0.1


def write_oxts(drive, poses, stamps):
    """oxts.txt as tools/xviz_to_kitti.py writes it: the forward speed (m/s) and the yaw rate (rad/s) in
    columns 7 and 9, from the exact ground truth."""
    steps = np.diff(poses[:, :3, 3], axis=0)
    yaws = np.unwrap(np.arctan2(poses[:, 1, 0], poses[:, 0, 0]))
    intervals = np.diff(stamps)
    oxts = np.zeros((len(poses), 9))
    oxts[:-1, 6] = np.linalg.norm(steps, axis=1) / intervals
    oxts[:-1, 8] = np.diff(yaws) / intervals
    oxts[-1] = oxts[-2]
    np.savetxt(os.path.join(drive, "oxts.txt"), oxts)


def slide_sideways(poses):
    """The positions moved SLIDE_M a scan along each pose's own y axis over SLIDE_SCANS scans."""
    slid = poses.copy()
    offsets = SLIDE_M * np.clip(np.arange(len(poses)) - SLIDE_FIRST + 1, 0, SLIDE_SCANS)
    slid[:, :3, 3] += offsets[:, None] * poses[:, :3, 1]
    return slid


def drive_rows(table):
    """t_rel and r_rel of the drive table's rows, by (method, truth)."""
    rows = {}
    for line in table.splitlines():
        words = line.split()
        if len(words) == 15 and words[0] == "sim":
            rows[(words[1], words[2])] = (float(words[5]), float(words[6]))
    return rows


class AccuracyReal(unittest.TestCase):
    def test_a_straying_ground_truth_is_found_and_its_clear_segments_scored(self):
        tools = os.path.join(BUILD, "devel", "lib", "elo_odometry")
        with tempfile.TemporaryDirectory() as work:
            drive = os.path.join(work, "drives", "sim")
            subprocess.run([os.path.join(tools, "elo_sim"), "--world", "urban", "--trajectory", "curves", "--frames",
                            str(SCANS), "--deskewed", "0", "--time-convention", "azimuth", "--seed", "3", "--threads",
                            "2", "--output", drive], check=True, capture_output=True)
            rows = np.loadtxt(os.path.join(drive, "poses.txt")).reshape(-1, 3, 4)
            poses = np.tile(np.eye(4), (len(rows), 1, 1))
            poses[:, :3, :] = rows
            write_oxts(drive, poses, np.loadtxt(os.path.join(drive, "times.txt")))
            np.savetxt(os.path.join(drive, "poses.txt"), slide_sideways(poses)[:, :3, :].reshape(len(poses), 12))
            output = os.path.join(work, "out")
            done = subprocess.run(["bash", os.path.join(SOURCE, "tools", "accuracy_real.sh"), BUILD,
                                   os.path.join(work, "drives")],
                                  env=dict(os.environ, ACCURACY_REAL_OUTPUT=output, START_EVERY="100", THREADS="2"),
                                  capture_output=True, text=True)
            self.assertEqual(done.returncode, 0, done.stdout + done.stderr)
            with open(os.path.join(output, "table.txt")) as table:
                text = table.read()
            rows = drive_rows(text)
            self.assertEqual(set(rows), {("elo-f2m", "stamps"), ("elo-f2m", "instants"), ("elo-f2m", "clear")}, text)
            straying, clear = rows[("elo-f2m", "stamps")][0], rows[("elo-f2m", "clear")][0]
            # The drive sets off from rest: 1 m of sliding over its first 18 m is several per cent of every
            # segment that holds it; the odometry's own drift on simulated sweeps is a few hundredths.
            self.assertGreater(straying, 1.0, text)
            self.assertLess(clear, 0.2, text)
            # The forward-backward gap and the start table have their rows too.
            self.assertRegex(text, r"\nsim +\d+\.\d +\d+\.\d+ +\d+\.\d+ +\d+\.\d+\n")
            self.assertRegex(text, r"\nsim +0 +\d+\.\d ")


if __name__ == "__main__":
    if len(sys.argv) < 2 or not os.path.isdir(os.path.join(sys.argv[1], "devel")):
        sys.exit(__doc__)
    BUILD = sys.argv.pop(1)
    unittest.main()
