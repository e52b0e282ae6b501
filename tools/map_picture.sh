#!/usr/bin/env bash
# Draws docs/map.png: the drive's map of a simulated urban drive, seen from above, each voxel's point
# coloured by its height, with the driven path. Runs elo_sim, then elo_run --map, then gnuplot.
#   tools/map_picture.sh [BUILD_DIR] [FRAMES]     (defaults: build, 300 frames, about 270 m)
set -euo pipefail
build=${1:-build}
frames=${2:-300}
bin="$build/devel/lib/elo_odometry"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$bin/elo_sim" --world urban --trajectory curves --frames "$frames" --seed 1 --sensor hdl64 --output "$out/seq" >/dev/null
"$bin/elo_run" --input "$out/seq" --output "$out/poses.txt" --map "$out/map.pcd" --quiet | grep '^map'
# The binary PCD's points as text (x y z), and the poses' positions (KITTI rows: x at 4, y at 8).
python3 - "$out/map.pcd" "$out/map.txt" <<'PY'
import struct, sys
data = open(sys.argv[1], 'rb').read()
start = data.index(b'DATA binary\n') + len(b'DATA binary\n')
header = data[:start].decode()
count = int([line for line in header.splitlines() if line.startswith('POINTS')][0].split()[1])
with open(sys.argv[2], 'w') as text:
    for i in range(count):
        x, y, z = struct.unpack_from('<3f', data, start + 28 * i)
        text.write(f'{x:.2f} {y:.2f} {z:.2f}\n')
PY
awk '{print $4, $8}' "$out/poses.txt" > "$out/path.txt"
gnuplot <<GP
set terminal pngcairo size 1400,1000 noenhanced
set output 'docs/map.png'
set size ratio -1
set title "drive's map: simulated urban drive, $frames HDL-64E scans, 0.2 m voxels, seen from above (colour: height)"
set xlabel 'x (m)'
set ylabel 'y (m)'
set cblabel 'z (m)'
set cbrange [-2.5:6]
set palette defined (0 '#303060', 1 '#3070c0', 2 '#40b080', 3 '#e0d040', 4 '#e05030')
unset key
plot '$out/map.txt' using 1:2:3 with dots palette, '$out/path.txt' using 1:2 with lines lw 2 lc rgb 'black'
GP
echo "wrote docs/map.png"
