#!/usr/bin/env bash
# Accuracy on simulated sequences with exact ground truth: every world with the HDL-64E, every other
# sensor in the urban world (about 1 km each), the paper's Table II/III ablation on one urban drive
# (Table III also with the normal gate opened, and with the simulator's clutter), and a drive through
# KITTI 00's ground-truth poses when the shared data has them. Prints one table (KITTI metric t_rel, its
# horizontal part t_xy, r_rel, ATE, odometry FPS), then Table III on the real scans when the shared data has them: the gap
# between runs forward and in reverse, which needs no ground truth; then the deskew table (issue 15,
# docs/deskew_accuracy.md): urban and highway drives with the HDL-64E, VLP-16 and OS1-64 as instantaneous
# scans and as sweeps with motion in both time conventions, without and with deskew.
# Usage:
#   tools/accuracy.sh BUILD_DIR [SHARED_DATA_DIR] [deskew]
# Works in BUILD_DIR/accuracy/ (scans are deleted after each run, trajectories kept); the table is
# also written to BUILD_DIR/accuracy/table.txt. Takes about 40 minutes on 2 cores, plus about 30 for the
# deskew table; `deskew` as the third argument makes only the deskew table.
set -euo pipefail
build=${1:-build}
data=${2:-../shared/data}
only=${3:-}
bin="$build/devel/lib/elo_odometry"
configs="$(dirname "$0")/../config"
work="$build/accuracy"
for tool in elo_sim elo_run elo_eval; do
  [ -x "$bin/$tool" ] || { echo "accuracy: $bin/$tool is missing; build first (make build)" >&2; exit 1; }
done
rm -rf "$work"
mkdir -p "$work"
table="$work/table.txt"
: >"$table"
[ "$only" = deskew ] ||
  printf '%-18s %-8s %-5s %7s %9s %9s %9s %15s %8s %6s\n' world/drive sensor mode frames length_m 't_rel_%' \
    't_xy_%' 'r_rel_deg/100m' ATE_m FPS | tee "$table"

# evaluate LABEL SENSOR MODE [--set KEY=VALUE]...: runs the odometry, configured for SENSOR, over the
# sequence simulated for LABEL and SENSOR and adds a table row; --set variants are named in the row.
evaluate() {
  local label=$1 sensor=$2 mode=$3
  shift 3
  local dir="$work/${label//\//-}-$sensor"
  local variant="" arg
  for arg in "$@"; do
    [ "$arg" = --set ] || variant="${variant:+$variant,}$arg"
  done
  local name="$mode${variant:+-${variant//[.=]/_}}"
  local fps
  fps=$("$bin/elo_run" --input "$dir/sequence" --output "$dir/$name.txt" --config "$configs/$sensor.yaml" \
    --mode "$mode" --quiet "$@" |
    awk '/^FPS:/ {print $2}')
  "$bin/elo_eval" --gt "$dir/sequence/poses.txt" --est "$dir/$name.txt" | tail -n 1 |
    awk -v w="$label${variant:+ $variant}" -v s="$sensor" -v m="$mode" -v f="$fps" \
      '{printf "%-18s %-8s %-5s %7d %9.1f %9.3f %9.3f %15.4f %8.3f %6.1f\n", w, s, m, $2, $3, $4, $9, $5, $8, f}' |
    tee -a "$table"
}

# simulate_and_evaluate LABEL SENSOR MODES ELO_SIM_ARGS...: one sequence, one table row per mode.
simulate_and_evaluate() {
  local label=$1 sensor=$2 modes=$3
  shift 3
  local dir="$work/${label//\//-}-$sensor"
  "$bin/elo_sim" --sensor "$sensor" --seed 7 --output "$dir/sequence" "$@" >&2
  for mode in $modes; do
    evaluate "$label" "$sensor" "$mode"
  done
  rm -rf "$dir/sequence/velodyne"
}

# deskew_table: each world and sensor simulated three times from the same seed: instantaneous scans (no
# per-point times), and the sweep with motion in each time convention of elo_sim --deskewed 0: field
# (PCD scans with per-point times, ground truth at the sweep's start) and azimuth (KITTI .bin without
# times, ground truth at mid-sweep). Each runs in both modes without deskew (time_source none) and, for
# the distorted ones, with its convention's time source.
deskew_table() {
  printf '\n%-15s %-7s %-22s %-5s %9s %9s %9s %15s %8s\n' 'deskew drive' sensor 'scans, time_source' mode \
    length_m 't_rel_%' 't_xy_%' 'r_rel_deg/100m' ATE_m | tee -a "$table"
  local cell world sensor frames scans source mode dir
  # The ctest gates' drives (test/pipeline/test_deskew_accuracy.cpp), from rest: urban up to 10 m/s (166 m),
  # highway up to 25 m/s (190 m). The VLP-16 loses the highway drive even on instantaneous scans.
  for cell in urban:hdl64:200 highway:hdl64:160 urban:vlp16:200 highway:os1-64:160 urban:os1-64:200; do
    IFS=: read -r world sensor frames <<<"$cell"
    for scans in instantaneous field azimuth; do
      dir="$work/deskew-$world-$sensor-$scans"
      local sim_args=(--deskewed 1)
      [ "$scans" = field ] && sim_args=(--deskewed 0 --time-convention field --format pcd)
      [ "$scans" = azimuth ] && sim_args=(--deskewed 0 --time-convention azimuth)
      "$bin/elo_sim" --sensor "$sensor" --seed 7 --world "$world" --trajectory curves --frames "$frames" \
        --output "$dir/sequence" "${sim_args[@]}" >&2
      for source in none $([ "$scans" = instantaneous ] || echo "$scans"); do
        for mode in f2m f2f; do
          "$bin/elo_run" --input "$dir/sequence" --output "$dir/$mode-$source.txt" --config "$configs/$sensor.yaml" \
            --mode "$mode" --quiet --set "deskew.time_source=$source" >/dev/null
          "$bin/elo_eval" --gt "$dir/sequence/poses.txt" --est "$dir/$mode-$source.txt" | tail -n 1 |
            awk -v w="$world/curves" -v s="$sensor" -v k="$scans, $source" -v m="$mode" \
              '{printf "%-15s %-7s %-22s %-5s %9.1f %9.3f %9.3f %15.4f %8.3f\n", w, s, k, m, $3, $4, $9, $5, $8}' |
            tee -a "$table"
        done
      done
      rm -rf "$dir/sequence/velodyne" "$dir"/sequence/*.pcd
    done
  done
}

if [ "$only" = deskew ]; then
  deskew_table
  echo "table: $table"
  exit 0
fi

# Frames for about 1 km from rest at each world's cruise speed (urban 10, highway 25, country 18,
# parking 5 m/s; 1.5 m/s^2 to get there).
simulate_and_evaluate urban/curves hdl64 "f2m f2f" --world urban --trajectory curves --frames 1050
simulate_and_evaluate highway/curves hdl64 "f2m f2f" --world highway --trajectory curves --frames 490
simulate_and_evaluate country/hill hdl64 "f2m f2f" --world country --trajectory hill --frames 620
simulate_and_evaluate parking/uturn hdl64 "f2m f2f" --world parking --trajectory uturn --frames 2020
for sensor in vlp16 vlp32 os1-64 os1-128; do
  simulate_and_evaluate urban/roundabout "$sensor" f2m --world urban --trajectory roundabout --frames 1050
done
# The paper's Table II (each projection alone) and Table III (each normal estimator) on one urban drive.
ablation="$work/urban-ablation-hdl64"
"$bin/elo_sim" --sensor hdl64 --seed 7 --output "$ablation/sequence" --world urban --trajectory curves \
  --frames 400 >&2
for variant in registration.terms=fused registration.terms=spherical_all registration.terms=spherical_nonground \
  registration.terms=bev_ground normals.method=eigen normals.method=cross_product; do
  evaluate urban/ablation hdl64 f2m --set "$variant"
done
# Table III in the paper's pipeline, the scan/model normal gate opened from our 30 to 90 degrees: the gate
# drops the cross product's worst normals, which is what lets it keep up on simulated drives
# (docs/accuracy.md, Table III).
for method in range_adaptive eigen cross_product; do
  evaluate urban/ablation hdl64 f2m --set registration.max_normal_angle_deg=90 --set normals.method=$method
done
rm -rf "$ablation/sequence/velodyne"
# Table III again on the same drive with clutter: beams reaching into leaves, mixed pixels at depth edges.
cluttered="$work/urban-ablation_clutter-hdl64"
"$bin/elo_sim" --sensor hdl64 --seed 7 --output "$cluttered/sequence" --world urban --trajectory curves \
  --frames 400 --foliage-depth 1.0 --mixed-pixels 0.5 >&2
for variant in normals.method=range_adaptive normals.method=eigen normals.method=cross_product; do
  evaluate urban/ablation_clutter hdl64 f2m --set "$variant"
done
rm -rf "$cluttered/sequence/velodyne"
kitti_poses="$data/kitti_gt/poses/00.txt"
if [ -f "$kitti_poses" ]; then
  # KITTI 00's 4541 poses (3.7 km) through an urban world.
  simulate_and_evaluate urban/kitti00 hdl64 f2m --world urban --poses "$kitti_poses"
else
  echo "accuracy: no KITTI ground truth at $kitti_poses (shared data absent); KITTI 00 drive skipped" >&2
fi
# Table III on the real scans, which have no ground truth: each estimator runs over every scan, every
# 2nd and every 3rd, forward and in reverse, and the two runs' gap is printed.
real_scans="$data/real/hdl64_drive_a"
if [ -d "$real_scans" ]; then
  printf '\n%-26s %6s %6s %9s %9s %9s\n' 'real scans (no truth)' stride scans length_m gap_m gap_deg | tee -a "$table"
  for stride in 1 2 3; do
    for method in range_adaptive eigen cross_product; do
      run="$work/real-$method-stride$stride"
      for direction in forward reverse; do
        "$bin/elo_run" --input "$real_scans" --output "$run-$direction.txt" --config "$configs/hdl64.yaml" --quiet \
          --stride "$stride" $([ "$direction" = reverse ] && echo --reverse) --set "normals.method=$method" >/dev/null
      done
      "$bin/elo_eval" --est "$run-forward.txt" --reverse "$run-reverse.txt" |
        awk -v m="$method" -v k="$stride" '{printf "%-26s %6d %6d %9.1f %9.4f %9.4f\n", m, k, $8, $11, $3, $5}' |
        tee -a "$table"
    done
  done
else
  echo "accuracy: no real scans at $real_scans (shared data absent); their forward-backward Table III skipped" >&2
fi
deskew_table
echo "table: $table"
