#!/usr/bin/python3
"""tools/oxts_consistency.py on a synthetic drive: a car on a circle at 10 m/s turning at 0.05 rad/s,
its OXTS yaw rate exact. The ground truth agrees with the yaw rate and travels along its heading and its
x axis; an odometry that turns 0.01 deg a scan too far is 0.5 deg off the yaw rate over a window of 50
scans, and one that climbs 1 m in 100 with its x axis level travels 0.573 deg above it. --strays finds
where a ground truth's positions slide sideways under an unchanged heading."""
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

TOOL = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools", "oxts_consistency.py")
SCANS = 120
PERIOD = 0.1
SPEED = 10.0
YAW_RATE = 0.05


def circle_poses(extra_yaw_per_scan=0.0, grade=0.0):
    poses = []
    for k in range(SCANS):
        heading = YAW_RATE * PERIOD * k
        radius = SPEED / YAW_RATE
        pose = np.eye(4)
        turn = heading + np.radians(extra_yaw_per_scan) * k
        pose[:2, :2] = [[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]]
        pose[:3, 3] = [radius * np.sin(heading), radius * (1.0 - np.cos(heading)), grade * SPEED * PERIOD * k]
        poses.append(pose[:3, :].reshape(-1))
    return np.array(poses)


def rows_of(output):
    """The six figures of each row after the header, by the trajectory's name (a file's base name)."""
    rows = {}
    for line in output.splitlines()[1:]:
        words = line.split()
        rows[os.path.basename(" ".join(words[:-6]))] = [float(w) for w in words[-6:]]
    return rows


def write_drive(drive, poses, speed, yaw_rate):
    np.savetxt(os.path.join(drive, "poses.txt"), poses)
    np.savetxt(os.path.join(drive, "times.txt"), PERIOD * np.arange(SCANS))
    oxts = np.zeros((SCANS, 9))
    oxts[:, 6] = speed
    oxts[:, 8] = yaw_rate
    np.savetxt(os.path.join(drive, "oxts.txt"), oxts)


def strays(drive):
    done = subprocess.run([sys.executable, TOOL, "--strays", drive], capture_output=True, text=True)
    return done.returncode, done.stdout.strip(), done.stderr


class OxtsConsistency(unittest.TestCase):
    def test_exact_drive_and_an_odometry_that_turns_too_far(self):
        with tempfile.TemporaryDirectory() as drive:
            np.savetxt(os.path.join(drive, "poses.txt"), circle_poses())
            np.savetxt(os.path.join(drive, "times.txt"), PERIOD * np.arange(SCANS))
            oxts = np.zeros((SCANS, 9))
            oxts[:, 6] = SPEED
            oxts[:, 8] = YAW_RATE
            np.savetxt(os.path.join(drive, "oxts.txt"), oxts)
            turning = os.path.join(drive, "turns_too_far.txt")
            np.savetxt(turning, circle_poses(extra_yaw_per_scan=0.01))
            climbing = os.path.join(drive, "climbs_level.txt")
            np.savetxt(climbing, circle_poses(grade=0.01))
            done = subprocess.run([sys.executable, TOOL, drive, turning, climbing], capture_output=True, text=True)
            self.assertEqual(done.returncode, 0, done.stderr)
            rows = rows_of(done.stdout)
            truth = rows["ground truth"]
            self.assertAlmostEqual(truth[0], 0.0, places=6)  # turn - yaw rate, mean
            self.assertAlmostEqual(truth[2], 0.0, places=6)  # travel - heading, mean
            self.assertAlmostEqual(truth[4], 0.0, places=6)  # climb - pitch, mean
            self.assertAlmostEqual(rows["turns_too_far.txt"][0], 0.5, places=6)
            self.assertAlmostEqual(rows["turns_too_far.txt"][1], 0.5, places=6)
            self.assertAlmostEqual(rows["climbs_level.txt"][0], 0.0, places=6)
            # The chord of 5 scans of the circle is a little shorter than its arc: 0.573 deg to 0.01.
            self.assertAlmostEqual(rows["climbs_level.txt"][4], np.degrees(np.arctan(0.01)), places=2)

    def test_strays_where_the_positions_slide_sideways(self):
        with tempfile.TemporaryDirectory() as drive:
            # On the circle the truth travels along its heading: what OXTS's yaw rate gives a sensor ahead
            # of the turning centre is a steady angle, taken off with the drive's median. Nothing strays.
            write_drive(drive, circle_poses(), SPEED, YAW_RATE)
            self.assertEqual(strays(drive)[:2], (0, ""))
            # Straight along x at 1 m a scan, the positions sliding 0.1 m sideways a scan over scans 50-70
            # (5.7 deg) under an unchanged heading: a window of 5 scans holding 3 or more of those 20
            # slides (3.4 deg and more) strays, those starting at scans 48-67, which cover scans 48-72.
            straight = np.tile(np.eye(4)[:3, :].reshape(-1), (SCANS, 1))
            straight[:, 3] = np.arange(SCANS)
            straight[:, 7] = 0.1 * np.clip(np.arange(SCANS) - 50, 0, 20)
            write_drive(drive, straight, 10.0, 0.0)
            returncode, ranges, report = strays(drive)
            self.assertEqual(returncode, 0, report)
            self.assertEqual(ranges, "48-72")
            self.assertIn("25 of 120 scans", report)
            # Two stretches, comma-separated as elo_eval --exclude-frames reads them.
            straight[:, 7] += 0.1 * np.clip(np.arange(SCANS) - 100, 0, 10)
            write_drive(drive, straight, 10.0, 0.0)
            self.assertEqual(strays(drive)[1], "48-72,98-112")

    def test_strays_needs_an_oxts_row_a_pose(self):
        with tempfile.TemporaryDirectory() as drive:
            write_drive(drive, circle_poses(), SPEED, YAW_RATE)
            np.savetxt(os.path.join(drive, "oxts.txt"), np.zeros((SCANS - 1, 9)))
            returncode, _, report = strays(drive)
            self.assertEqual(returncode, 2)
            self.assertIn("oxts.txt has 119 rows for 120 poses", report)
            self.assertEqual(strays(os.path.join(drive, "nowhere"))[0], 2)
            np.savetxt(os.path.join(drive, "poses.txt"), circle_poses()[:5])
            np.savetxt(os.path.join(drive, "oxts.txt"), np.zeros((5, 9)))
            returncode, _, report = strays(drive)
            self.assertEqual(returncode, 2)
            self.assertIn("5 scans, too few for windows of 5", report)

    def test_a_trajectory_of_other_scans_is_refused(self):
        with tempfile.TemporaryDirectory() as drive:
            np.savetxt(os.path.join(drive, "poses.txt"), circle_poses())
            np.savetxt(os.path.join(drive, "times.txt"), PERIOD * np.arange(SCANS))
            np.savetxt(os.path.join(drive, "oxts.txt"), np.zeros((SCANS, 9)))
            short = os.path.join(drive, "short.txt")
            np.savetxt(short, circle_poses()[:100])
            done = subprocess.run([sys.executable, TOOL, drive, short], capture_output=True, text=True)
            self.assertEqual(done.returncode, 2)
            self.assertIn("100 poses for 120 OXTS samples", done.stderr)
            missing = subprocess.run([sys.executable, TOOL, os.path.join(drive, "nowhere")], capture_output=True,
                                     text=True)
            self.assertEqual(missing.returncode, 2)


if __name__ == "__main__":
    unittest.main()
