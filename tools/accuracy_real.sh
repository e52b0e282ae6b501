#!/usr/bin/env bash
# Accuracy on the real KITTI-raw drives with ground truth (issue 43, docs/real_drives.md): every drive
# under DRIVES_DIR (a subdirectory with velodyne/ and poses.txt, as tools/xviz_to_kitti.py writes it) is
# run with config/kitti.yaml and scored over segments of 10-100 m. Prints three tables; those with the
# ground truth score against it at its stamps (OXTS's, rounded to 10 ms) and interpolated to the scans'
# uniform instants (elo_eval --gt-times; docs/real_drives.md):
#   - per drive: scans, length, t_rel, r_rel, t_rel_xy, ATE and the error breakdown (elo_eval
#     --breakdown: heading, pitch, roll in deg/100 m; along-track, signed, cross-track and height in %);
#     with KISS_RUN (a kiss_run binary, /work/shared/tools/kiss/setup.sh) also KISS-ICP's rows; on a
#     drive whose ground truth strays (tools/oxts_consistency.py --strays), a third row over the segments
#     clear of its strays (elo_eval --exclude-frames);
#   - without the ground truth: the gap between ELO's run and a run over the same scans driven backwards
#     (elo_run --reverse, elo_eval --reverse), which OXTS's errors do not enter;
#   - start in motion: runs of 11 scans started at scan 0, every 60th scan (START_EVERY) and the scan
#     where the car is fastest (oxts.txt), each scored by the error of its 2nd and 11th pose against the
#     ground truth rebased to its first scan (elo_eval --start S --pose-errors 1,10), beside the 11th
#     pose's error of the drive's own run over the same scans (tracking, no start).
# Usage:
#   [START_EVERY=N] [THREADS=N] [ACCURACY_REAL_OUTPUT=DIR] tools/accuracy_real.sh BUILD_DIR DRIVES_DIR [f2m|f2f]
# Works in ACCURACY_REAL_OUTPUT (default BUILD_DIR/accuracy_real/, emptied first; trajectories kept); the
# tables are also written to table.txt there. Exits 0, saying where it looked, when DRIVES_DIR holds no drive.
set -euo pipefail
build=${1:-build}
drives_dir=${2:-../real_drives}
mode=${3:-f2m}
bin="$build/devel/lib/elo_odometry"
config="$(dirname "$0")/../config/kitti.yaml"
work=${ACCURACY_REAL_OUTPUT:-$build/accuracy_real}
segments=10,20,50,100
# A segment starts at every scan: these drives are 108-188 scans long, too few for the devkit's every 10th.
segment_step=1
start_every=${START_EVERY:-60}
start_frames=11
threads=${THREADS:-2}

drives=()
for dir in "$drives_dir"/*/; do
  [ -d "$dir/velodyne" ] && [ -f "$dir/poses.txt" ] && drives+=("${dir%/}")
done
if [ ${#drives[@]} -eq 0 ]; then
  echo "no real drives under $drives_dir: see docs/real_drives.md"
  exit 0
fi
for tool in elo_run elo_eval; do
  [ -x "$bin/$tool" ] || { echo "accuracy_real: $bin/$tool is missing; build first (make build)" >&2; exit 1; }
done
rm -rf "$work"
mkdir -p "$work"
table="$work/table.txt"
: >"$table"

# elo_eval, its note on the instants it moved the ground truth to left out of the tables; its errors kept.
evaluate() {
  "$bin/elo_eval" "$@" 2> >(grep -v -e 'interpolated to uniform instants' -e 'are left out' >&2)
}

# strayingScans DRIVE: the scans where the ground truth's direction of travel strays from what OXTS's own
# speed and yaw rate give ("A-B,C-D"; nothing where it holds together or oxts.txt is absent).
strayingScans() {
  if [ -f "$1/oxts.txt" ]; then "$(dirname "$0")/oxts_consistency.py" --strays "$1" 2>/dev/null; fi
}

# truthAt DRIVE TRUTH: elo_eval's options for the ground truth at its stamps, at the scans' instants, or
# at its stamps over the segments clear of its strays (the drive table's loop finds them, in `strays`).
truthAt() {
  case $2 in
    instants) echo "--gt $1/poses.txt --gt-times $1/times.txt" ;;
    clear) echo "--gt $1/poses.txt --exclude-frames $strays" ;;
    *) echo "--gt $1/poses.txt" ;;
  esac
}

# score DRIVE METHOD POSES TRUTH: one row of the drive table, from elo_eval's KITTI row and breakdown row.
score() {
  local drive=$1 method=$2 poses=$3 truth=$4
  # shellcheck disable=SC2046  # truthAt's options are words
  evaluate $(truthAt "$drive" "$truth") --est "$poses" --segments "$segments" \
    --segment-step "$segment_step" --breakdown |
    awk -v d="$(basename "$drive")" -v m="$method" -v g="$truth" '
      $1 == "sequence" { table++; next }
      table == 1 { scans = $2; length_m = $3; t = $4; r = $5; ate = $8; txy = $9 }
      table == 2 { printf "%-6s %-7s %-8s %6d %9.1f %8.3f %15.3f %8.3f %7.3f %9.3f %7.3f %7.3f %+8.3f %8.3f %9.3f\n",
                          d, m, g, scans, length_m, t, r, txy, ate, $2, $3, $4, $5, $6, $7 }' |
    tee -a "$table"
}

# truths DRIVE STRAYS: the ground truth at the scans' instants needs the stamps, times.txt; its clear
# segments a drive where it strays.
truths() {
  echo stamps
  if [ -f "$1/times.txt" ]; then echo instants; fi
  if [ -n "$2" ]; then echo clear; fi
}

printf '%-6s %-7s %-8s %6s %9s %8s %15s %8s %7s %9s %7s %7s %8s %8s %9s\n' drive method truth scans length_m 't_rel_%' \
  'r_rel_deg/100m' 't_xy_%' ATE_m heading pitch roll 'along_%' 'cross_%' 'height_%' | tee -a "$table"
for drive in "${drives[@]}"; do
  name=$(basename "$drive")
  "$bin/elo_run" --input "$drive" --output "$work/$name.txt" --config "$config" --mode "$mode" \
    --threads "$threads" --quiet >"$work/$name.log"
  if [ -n "${KISS_RUN:-}" ]; then
    "$KISS_RUN" "$drive/velodyne" --output "$work/${name}_kiss.txt" --threads "$threads" >"$work/${name}_kiss.log"
  fi
  strays=$(strayingScans "$drive")
  for truth in $(truths "$drive" "$strays"); do
    score "$drive" "elo-$mode" "$work/$name.txt" "$truth"
    [ -z "${KISS_RUN:-}" ] || score "$drive" kiss-icp "$work/${name}_kiss.txt" "$truth"
  done
done
echo "(segments of $segments m starting at every scan; heading, pitch, roll in deg/100m, mean absolute;" \
  "along-track signed: + the estimate travels too far; clear: at the stamps, the segments holding no scan" \
  "where the ground truth's direction of travel strays, tools/oxts_consistency.py --strays)" | tee -a "$table"

printf '\n%-6s %9s %12s %12s %10s\n' drive length_m gap_m gap_deg 'gap_%' | tee -a "$table"
for drive in "${drives[@]}"; do
  name=$(basename "$drive")
  "$bin/elo_run" --input "$drive" --output "$work/${name}_reverse.txt" --config "$config" --mode "$mode" \
    --threads "$threads" --quiet --reverse >"$work/${name}_reverse.log"
  "$bin/elo_eval" --est "$work/$name.txt" --reverse "$work/${name}_reverse.txt" |
    awk -v d="$name" '{ printf "%-6s %9.1f %12.4f %12.4f %10.3f\n", d, $11, $3, $5, 100 * $3 / $11 }' | tee -a "$table"
done
echo "(forward-backward gap: the run's last pose times the reverse run's, no ground truth; errors that" \
  "change sign with the direction of travel, as a scale error does, cancel in it)" | tee -a "$table"

# starts DRIVE SCANS: scan 0, every 60th scan, and the scan where the car is fastest, of those followed
# by 10 more scans.
starts() {
  local drive=$1 scans=$2 last=$(($2 - start_frames)) s
  for ((s = 0; s <= last; s += start_every)); do echo "$s"; done
  if [ -f "$drive/oxts.txt" ]; then
    awk -v last="$last" 'NR - 1 <= last && (best == "" || $7 > fastest) { fastest = $7; best = NR - 1 }
                         END { if (best != "") print best }' "$drive/oxts.txt"
  fi
}

# poseErrors DRIVE START POSES TRUTH: the errors of the 2nd and the 11th pose.
poseErrors() {
  # shellcheck disable=SC2046  # truthAt's options are words
  evaluate $(truthAt "$1" "$4") --est "$3" --start "$2" --pose-errors 1,$((start_frames - 1)) |
    awk '$2 == "pose" { table = 1; next } table { printf "%s ", $3 }'
}

# trackedSlice POSES START: a run's poses over the start's scans, as a trajectory of its own.
trackedSlice() {
  sed -n "$(($2 + 1)),$(($2 + start_frames))p" "$1" >"$work/tracked_slice.txt"
  echo "$work/tracked_slice.txt"
}

printf '\n%-6s %7s %9s %17s %17s %19s %19s %18s\n' drive start 'speed_m/s' '2nd_scan_stamps_m' '11th_scan_stamps_m' \
  '2nd_scan_instants_m' '11th_scan_instants_m' '11th_tracking_m' | tee -a "$table"
for drive in "${drives[@]}"; do
  name=$(basename "$drive")
  scans=$(find "$drive/velodyne" -name '*.bin' | wc -l)
  tracking_truth=stamps
  if [ -f "$drive/times.txt" ]; then tracking_truth=instants; fi
  for start in $(starts "$drive" "$scans" | sort -nu); do
    poses="$work/${name}_start_$start.txt"
    "$bin/elo_run" --input "$drive" --output "$poses" --config "$config" --mode "$mode" --threads "$threads" \
      --quiet --start "$start" --frames "$start_frames" >"$work/${name}_start_$start.log"
    speed=$( [ -f "$drive/oxts.txt" ] && awk -v s="$start" 'NR - 1 == s { print $7 }' "$drive/oxts.txt" || echo nan)
    at_instants="nan nan"
    [ -f "$drive/times.txt" ] && at_instants=$(poseErrors "$drive" "$start" "$poses" instants)
    tracked=$(poseErrors "$drive" "$start" "$(trackedSlice "$work/$name.txt" "$start")" "$tracking_truth" | awk '{ print $2 }')
    # shellcheck disable=SC2046,SC2086  # two numbers each
    printf '%-6s %7d %9.1f %17.3f %17.3f %19.3f %19.3f %18.3f\n' "$name" "$start" "$speed" \
      $(poseErrors "$drive" "$start" "$poses" stamps) $at_instants "$tracked" | tee -a "$table"
  done
done
echo "(error: translation of (gt_S^-1 gt_S+k)^-1 (est_0^-1 est_k), k = 1 and $((start_frames - 1)); against the" \
  "ground truth at its stamps and at the scans' uniform instants; tracking: the drive's run from its first" \
  "scan over the same scans, at the instants where times.txt gives them)" | tee -a "$table"
