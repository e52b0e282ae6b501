#!/usr/bin/env bash
# Compares two directories of poses written by tools/poses_of.sh, setting by setting. Without BOUND the
# poses must be the same bit for bit; with it, no pose entry may differ by more than BOUND (metres for
# translations). Prints by how much each setting's poses differ; skips, saying so, when POSES_A holds
# none (poses_of.sh found no real scans).
# usage: tools/same_poses.sh POSES_A POSES_B [BOUND]
set -euo pipefail
[ $# -eq 2 ] || [ $# -eq 3 ] || { echo "usage: $0 POSES_A POSES_B [BOUND]" >&2; exit 2; }
python3 - "$1" "$2" "${3:-0}" <<'PY'
import os, sys
dir_a, dir_b, bound = sys.argv[1], sys.argv[2], float(sys.argv[3])
settings = sorted(name for name in os.listdir(dir_a) if name.endswith(".txt")) if os.path.isdir(dir_a) else []
if not settings:
    print(f"same_poses: SKIPPED: no poses in {dir_a} (no real scans where they were written)")
    sys.exit(0)
failed = False
for name in settings:
    path_b = os.path.join(dir_b, name)
    if not os.path.exists(path_b):
        print(f"same_poses: {name}: none in {dir_b}")
        failed = True
        continue
    a = [list(map(float, line.split())) for line in open(os.path.join(dir_a, name))]
    b = [list(map(float, line.split())) for line in open(path_b)]
    if len(a) != len(b) or not a:
        print(f"same_poses: {name}: {len(a)} against {len(b)} poses")
        failed = True
        continue
    differing = sum(x != y for x, y in zip(a, b))
    largest = max(abs(u - v) for x, y in zip(a, b) for u, v in zip(x, y))
    if differing == 0:
        print(f"same_poses: {name}: the {len(a)} poses are the same bit for bit")
    else:
        print(f"same_poses: {name}: {differing} of {len(a)} poses differ, by up to {largest:.3g} "
              f"in an entry (m for translations; bound {bound:g})")
    failed |= largest > bound
sys.exit(1 if failed else 0)
PY
