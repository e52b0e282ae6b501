#!/usr/bin/python3
"""Real KITTI-raw drives with ground truth, from uber/xviz KITTI-converter output kept in git repositories.

Usage (Debian's python3 with python3-numpy):
  xviz_to_kitti.py GIT_DIR PREFIX OUT_DIR
    GIT_DIR  a (bare) git repository holding the converter's output, e.g. a `git clone --bare` of
             https://github.com/lukaasp/xviz-data (drive 2011_09_26_0001),
             https://github.com/yu1218jong/xviz_kitti (drives 0005 and 0027) or
             https://github.com/GwangRyul/kitti-data (drive 0002, PREFIX "2011_09_26/"); docs/real_drives.md
    PREFIX   the folder inside it that holds 0-frame.json and N-frame.glb, e.g.
             "2011_09_26_drive_0027_sync/" ("" for the repository's root)
Writes OUT_DIR in the KITTI layout that elo_run reads:
  velodyne/NNNNNN.bin  every scan, x y z reflectance float32 (the full HDL-64E scan; the converter stored
                       reflectance as a colour, R = 80 + 80 r, so r comes back in steps of 1/80)
  poses.txt            ground truth, KITTI 3x4 rows, the Velodyne frame, scan 0 = identity: the OXTS
                       RTK GPS/INS pose of each scan (KITTI devkit's convertOxtsToPose), moved from the
                       IMU to the Velodyne with calib_imu_to_velo.txt (the same for every KITTI date)
  times.txt            each scan's OXTS time, seconds from the first
  oxts.txt             per scan: lat lon alt roll pitch yaw, forward speed (m/s), forward acceleration
                       (m/s^2), yaw rate (rad/s); the speeds and rates are all the converter kept of OXTS
Facts worth knowing: the scans are raw (motion-distorted, 10 Hz, pose at the sensor facing forward, as
KITTI odometry); OXTS ground truth is good to a few cm and ~0.1 deg, so segments of 10-100 m score
translation only down to about 1 % on some drives (rotation scores finer); KITTI is CC BY-NC-SA 3.0.
"""
import json
import math
import os
import struct
import subprocess
import sys

import numpy as np

# calib_imu_to_velo.txt of KITTI raw (p_velo = R p_imu + T), identical for every recording date.
R_VELO_IMU = np.array([9.999976e-01, 7.553071e-04, -2.035826e-03, -7.854027e-04, 9.998898e-01,
                       -1.482298e-02, 2.024406e-03, 1.482454e-02, 9.998881e-01]).reshape(3, 3)
T_VELO_IMU = np.array([-8.086759e-01, 3.195559e-01, -7.997231e-01])
EARTH_RADIUS = 6378137.0


def git_show(git_dir, path):
    return subprocess.run(["git", "--git-dir", git_dir, "show", "HEAD:" + path],
                          capture_output=True, check=True).stdout


def read_glb(blob):
    """The JSON chunk and the binary chunk of a glTF binary file."""
    chunks, offset = [], 12
    while offset < len(blob):
        length, _ = struct.unpack("<I4s", blob[offset:offset + 8])
        chunks.append(blob[offset + 8:offset + 8 + length])
        offset += 8 + length
    return json.loads(chunks[0].rstrip(b" \x00")), (chunks[1] if len(chunks) > 1 else b"")


def accessor(doc, binary, ref):
    a = doc["accessors"][int(ref.split("/")[-1])]
    view = doc["bufferViews"][a["bufferView"]]
    dtype = {5126: np.float32, 5121: np.uint8}[a["componentType"]]
    return np.frombuffer(binary, dtype=dtype, count=a["count"] * 3,
                         offset=view.get("byteOffset", 0)).reshape(-1, 3)


def scalar(update, stream):
    series = update.get("time_series", [])
    for s in series:
        if stream in s.get("streams", []):
            return s["values"]["doubles"][s["streams"].index(stream)]
    return float("nan")


def rot(axis, a):
    c, s = math.cos(a), math.sin(a)
    return {"x": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


def oxts_pose(lat, lon, alt, roll, pitch, yaw, scale):
    """KITTI devkit convertOxtsToPose: Mercator position, Rz(yaw) Ry(pitch) Rx(roll)."""
    T = np.eye(4)
    T[0, 3] = scale * lon * math.pi * EARTH_RADIUS / 180
    T[1, 3] = scale * EARTH_RADIUS * math.log(math.tan((90 + lat) * math.pi / 360))
    T[2, 3] = alt
    T[:3, :3] = rot("z", yaw) @ rot("y", pitch) @ rot("x", roll)
    return T


def main(git_dir, prefix, out):
    os.makedirs(out + "/velodyne", exist_ok=True)
    timing = json.loads(git_show(git_dir, prefix + "0-frame.json"))["timing"]
    rows, stamps = [], []
    for k, entry in enumerate(timing):
        doc, binary = read_glb(git_show(git_dir, f"{prefix}{entry[3]}.glb"))
        update = doc["xviz"]["data"]["updates"][0]
        pose = update["poses"]["/vehicle_pose"]
        cloud = update["primitives"]["/lidar/points"]["points"][0]
        xyz = accessor(doc, binary, cloud["points"])
        reflectance = (accessor(doc, binary, cloud["colors"])[:, :1].astype(np.float32) - 80.0) / 80.0
        np.hstack([xyz, reflectance]).astype(np.float32).tofile(f"{out}/velodyne/{k:06d}.bin")
        origin = pose["map_origin"]
        rows.append((origin["latitude"], origin["longitude"], origin["altitude"], *pose["orientation"],
                     scalar(update, "/vehicle/velocity"), scalar(update, "/vehicle/acceleration"),
                     math.radians(scalar(update, "/vehicle/wheel_angle"))))  # the converter's name for OXTS wu (deg/s)
        stamps.append(pose["timestamp"])
    scale = math.cos(rows[0][0] * math.pi / 180)
    T_velo_imu = np.eye(4)
    T_velo_imu[:3, :3], T_velo_imu[:3, 3] = R_VELO_IMU, T_VELO_IMU
    T_imu_velo = np.linalg.inv(T_velo_imu)
    world_velo = [oxts_pose(*r[:6], scale) @ T_imu_velo for r in rows]
    first_inv = np.linalg.inv(world_velo[0])
    np.savetxt(f"{out}/poses.txt", np.array([(first_inv @ T)[:3, :].reshape(-1) for T in world_velo]), fmt="%.9e")
    np.savetxt(f"{out}/times.txt", np.array(stamps) - stamps[0], fmt="%.6f")
    np.savetxt(f"{out}/oxts.txt", np.array(rows), fmt="%.10f")
    print(f"{prefix or git_dir}: {len(rows)} scans written to {out}")


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    main(*sys.argv[1:])
