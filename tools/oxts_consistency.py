#!/usr/bin/python3
"""How far a real drive's OXTS ground truth agrees with OXTS's own yaw rate, and trajectories with both.

Usage (Debian's python3 with python3-numpy):
  oxts_consistency.py DRIVE_DIR [POSES ...]
  oxts_consistency.py --strays DRIVE_DIR
    DRIVE_DIR  a drive as tools/xviz_to_kitti.py writes it (poses.txt, times.txt, oxts.txt)
    POSES      trajectories of the same scans (KITTI poses, elo_run's or another odometry's)
--strays prints the scans where the ground truth's direction of travel strays, as ranges for elo_eval
--exclude-frames ("A-B,C-D"; an empty line when none does): over windows of 5 scans, one starting at
every scan, the angle between its direction of travel and its heading leaves the one OXTS's own speed and
yaw rate give (a sensor LEVER_M ahead of the turning centre, plus the drive's median: a mounting angle)
by more than STRAY_DEG. A car does not slide sideways; GPS positions in a town can.
Prints, for the ground truth and each trajectory, two figures that need nothing but OXTS itself
(docs/real_drives.md, "What limits the figures"):
  turn - yaw rate   over windows of 50 scans (one starting every 5th scan): the heading change the
                    trajectory makes, minus OXTS's yaw rate (its rate about the vehicle's up axis,
                    oxts.txt) integrated over the stamps; mean and rms, deg. OXTS's heading leaving
                    its own yaw rate is the ground truth's heading error, or the yaw rate's.
  travel - heading  over windows of 5 scans: the angle between the direction of travel and the heading
                    (half the window's turn taken off), mean and standard deviation, deg. A car's is a
                    steady mounting angle plus what the sensor's lever arm gets from the yaw rate; a
                    ground truth whose positions wander shows in its spread.
  climb - pitch     the same in the vertical: the angle of the direction of travel above the sensor's
                    x axis (half the window's change of pitch taken off). A car's is steady but for its
                    body pitching on the springs; a ground truth whose altitude wanders shows in its
                    spread, and in the height error elo_eval --breakdown gives.
"""
import os
import sys

import numpy as np

TURN_WINDOW = 50
TRAVEL_WINDOW = 5
WINDOW_STEP = 5
# KITTI's Velodyne is 0.81 m ahead of its OXTS unit (calib_imu_to_velo), taken as the turning centre: on
# drive 0005 levers of 0-1.2 m and bounds of 2-3 deg find the same two long stretches, and leave the same
# verdict on the segments clear of them (docs/real_drives.md).
LEVER_M = 0.81
STRAY_DEG = 2.5


def read_poses(path):
    rows = np.loadtxt(path, ndmin=2).reshape(-1, 3, 4)
    poses = np.tile(np.eye(4), (len(rows), 1, 1))
    poses[:, :3, :] = rows
    return poses


def yaw_deg(rotation):
    return np.degrees(np.arctan2(rotation[1, 0], rotation[0, 0]))


def relative(poses, i, j):
    return np.linalg.inv(poses[i]) @ poses[j]


def integrated_yaw_rate_deg(drive):
    """OXTS's yaw rate (rad/s, oxts.txt's last column) integrated over the stamps, deg from scan 0."""
    rate = np.degrees(np.loadtxt(os.path.join(drive, "oxts.txt"), ndmin=2)[:, 8])
    stamps = np.loadtxt(os.path.join(drive, "times.txt"), ndmin=1)
    return np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(stamps))])


def turn_minus_yaw_rate(poses, yaw_rate):
    starts = range(0, len(poses) - TURN_WINDOW, WINDOW_STEP)
    return np.array([yaw_deg(relative(poses, i, i + TURN_WINDOW)[:3, :3]) - (yaw_rate[i + TURN_WINDOW] - yaw_rate[i])
                     for i in starts])


def pitch_deg(rotation):
    return np.degrees(np.arctan2(-rotation[2, 0], rotation[0, 0]))


def travel_off_heading_deg(step):
    """The direction of travel over a window's motion `step` off its heading (half the window's turn taken
    off); None standing still, with no direction of travel."""
    if np.linalg.norm(step[:2, 3]) < 0.5:
        return None
    return np.degrees(np.arctan2(step[1, 3], step[0, 3])) - yaw_deg(step[:3, :3]) / 2.0


def travel_off_axes(poses):
    """Per window of TRAVEL_WINDOW scans: the direction of travel off the heading and above the x axis."""
    sideways, upwards = [], []
    for i in range(0, len(poses) - TRAVEL_WINDOW, TRAVEL_WINDOW):
        step = relative(poses, i, i + TRAVEL_WINDOW)
        off_heading = travel_off_heading_deg(step)
        if off_heading is None:
            continue
        sideways.append(off_heading)
        # The x axis pitches nose down for a positive pitch: half the window's pitch change turns it up.
        upwards.append(np.degrees(np.arctan2(step[2, 3], np.linalg.norm(step[:2, 3]))) + pitch_deg(step[:3, :3]) / 2.0)
    return np.array(sideways), np.array(upwards)


def travel_off_oxts_deg(poses, oxts):
    """Per window of TRAVEL_WINDOW scans starting at every scan (NaN standing still): the direction of
    travel off the heading, less the angle OXTS's speed and yaw rate give a sensor LEVER_M ahead of the
    turning centre."""
    speed, yaw_rate = oxts[:, 6], oxts[:, 8]
    angles = np.full(len(poses) - TRAVEL_WINDOW, np.nan)
    for i in range(len(angles)):
        off_heading = travel_off_heading_deg(relative(poses, i, i + TRAVEL_WINDOW))
        if off_heading is None:
            continue
        window = slice(i, i + TRAVEL_WINDOW + 1)
        lever_angle = np.degrees(np.arctan2(LEVER_M * yaw_rate[window].mean(), speed[window].mean()))
        angles[i] = off_heading - lever_angle
    return angles


def frame_ranges(flags):
    """The runs of True in `flags` as "A-B,C-D"."""
    ranges, first = [], None
    for scan, flagged in enumerate(list(flags) + [False]):
        if flagged and first is None:
            first = scan
        elif not flagged and first is not None:
            ranges.append(f"{first}-{scan - 1}")
            first = None
    return ",".join(ranges)


def print_strays(drive):
    poses = read_poses(os.path.join(drive, "poses.txt"))
    oxts = np.loadtxt(os.path.join(drive, "oxts.txt"), ndmin=2)
    if len(oxts) != len(poses) or oxts.shape[1] < 9:
        raise ValueError(f"{drive}: oxts.txt has {len(oxts)} rows for {len(poses)} poses (one of 9 numbers a pose)")
    if len(poses) <= TRAVEL_WINDOW:
        raise ValueError(f"{drive}: {len(poses)} scans, too few for windows of {TRAVEL_WINDOW}")
    off = travel_off_oxts_deg(poses, oxts)
    off -= np.nanmedian(off)  # the mounting angle
    flags = np.zeros(len(poses), dtype=bool)
    for i in np.flatnonzero(np.abs(np.nan_to_num(off)) > STRAY_DEG):
        flags[i:i + TRAVEL_WINDOW + 1] = True
    print(frame_ranges(flags), flush=True)  # before the report on stderr, where both go to one pipe
    print(f"oxts_consistency: {flags.sum()} of {len(poses)} scans in windows straying more than {STRAY_DEG} deg "
          f"(rms {np.sqrt(np.nanmean(off ** 2)):.2f} deg)", file=sys.stderr)


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__)
        return 0 if len(argv) >= 2 else 2
    if argv[1] == "--strays":
        if len(argv) != 3:
            print(__doc__)
            return 2
        try:
            print_strays(argv[2])
        except (OSError, ValueError) as error:
            print(f"oxts_consistency: {error}", file=sys.stderr)
            return 2
        return 0
    drive = argv[1]
    try:
        yaw_rate = integrated_yaw_rate_deg(drive)
        trajectories = [("ground truth", read_poses(os.path.join(drive, "poses.txt")))]
        trajectories += [(path, read_poses(path)) for path in argv[2:]]
    except (OSError, ValueError) as error:
        print(f"oxts_consistency: {error}", file=sys.stderr)
        return 2
    print(f"{'trajectory':<40} {'turn - yaw rate: mean':>22} {'rms':>7} {'travel - heading: mean':>23} {'sd':>6} "
          f"{'climb - pitch: mean':>20} {'sd':>6}")
    for name, poses in trajectories:
        if len(poses) != len(yaw_rate):
            print(f"oxts_consistency: {name} has {len(poses)} poses for {len(yaw_rate)} OXTS samples", file=sys.stderr)
            return 2
        if len(poses) <= TURN_WINDOW:
            print(f"oxts_consistency: {len(poses)} scans, too few for windows of {TURN_WINDOW}", file=sys.stderr)
            return 2
        turn = turn_minus_yaw_rate(poses, yaw_rate)
        sideways, upwards = travel_off_axes(poses)
        print(f"{name:<40} {turn.mean():>+22.3f} {np.sqrt(np.mean(turn ** 2)):>7.3f} "
              f"{sideways.mean():>+23.2f} {sideways.std():>6.2f} {upwards.mean():>+20.2f} {upwards.std():>6.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
