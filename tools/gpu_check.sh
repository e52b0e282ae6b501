#!/usr/bin/env bash
# The CUDA backend's check, in one table: the CPU/CUDA agreement tests (every stage, whole drives, maps,
# localization, a start in motion, refused registrations, the IMU), compute-sanitizer's memcheck,
# racecheck, initcheck and synccheck over a few real scans (deskew on, so that every kernel runs), over
# localization's map rendering and over a walk deskewed by the gyro, elo_run's poses on both backends
# with the IMU and with and without the overlapped upload, localization on both backends, and the
# CPU-against-GPU bench, frame-to-model, over simulated drives of three sensors and the real scans.
#
# On a GPU machine with a full build:   tools/gpu_check.sh build/devel/lib/elo_odometry [SCANS_DIR]
# From a kit packed by gpu_kit.sh:      bash .gpukit/setup.sh && source .gpukit/env.sh && tools/gpu_check.sh
# (the executables are then on PATH and the kit's scans are the default SCANS_DIR).
#
# GPU_CHECK_FRAMES (default 600) sets the length of each simulated drive. The exit status is 1 when a
# check fails; the bench figures are printed, never judged.
set -uo pipefail
bin=${1:-$(dirname "$(command -v elo_run)")}
scans=${2:-$(ls -d "$bin"/../scans 2>/dev/null || echo ../shared/data/real/hdl64_drive_a)}
frames=${GPU_CHECK_FRAMES:-600}
work=$(mktemp -d)
configs="$(dirname "$0")/../config"
trap 'rm -rf "$work"' EXIT
export CUDA_MODULE_LOADING=EAGER  # module loading stays out of the first frame's time
failures=0
rows=()

# Each row is printed as it is made too, so that a run cut short by the machine's time limit still says
# what it found; the table at the end gathers them.
row() {
  rows+=("$(printf '%-44s %s' "$1" "$2")")
  echo "[$(date +%T)] ${rows[-1]}"
}
fail() { failures=$((failures + 1)); row "$1" "FAIL: $2"; }

# The agreement tests: every stage and whole drives, CPU against CUDA.
check_agreement() {
  local log=$work/agreement.log
  "$bin/test_backend_agreement" --gtest_brief=1 >"$log" 2>&1
  local status=$? passed total cpu_only gpu_skipped
  passed=$(sed -n 's/.*\[  PASSED  \] \([0-9]*\) test.*/\1/p' "$log")
  total=$(sed -n 's/.*\[==========\] \([0-9]*\) tests.*ran.*/\1/p' "$log")
  # The tests of the CPU fallback skip where a GPU is usable, saying so; any other skip is a failure.
  cpu_only=$(grep -c "^a CUDA device is usable here" "$log")
  gpu_skipped=$(($(grep -c "Skipped$" "$log") - cpu_only))
  if [ "$status" -ne 0 ] || [ "$gpu_skipped" -ne 0 ]; then
    fail "agreement tests (test_backend_agreement)" "status $status, ${passed:-0} passed, $gpu_skipped skipped; $(grep -m3 FAILED "$log" | tr '\n' ' ')"
  else
    row "agreement tests (test_backend_agreement)" "${passed}/${total} passed ($cpu_only of the no-GPU fallback skip)"
  fi
}

# compute-sanitizer TOOL over elo_run through the CUDA backend on 5 scans of INPUT, with more options.
check_sanitizer() {
  local tool=$1 summary=$2 what=$3 input=$4 log=$work/$1.log
  shift 4
  if ! command -v compute-sanitizer >/dev/null; then fail "compute-sanitizer $tool" "not installed"; return; fi
  compute-sanitizer --tool "$tool" --error-exitcode 3 "$bin/elo_run" --input "$input" --output "$work/p.txt" \
    --frames 5 --quiet --backend cuda "$@" >"$log" 2>&1
  local status=$? found
  found=$(grep -m1 "$summary" "$log" | sed 's/^========= //')
  if [ "$status" -ne 0 ]; then fail "compute-sanitizer $tool, $what" "status $status; ${found:-no summary}"
  else row "compute-sanitizer $tool, $what" "${found:-no summary printed}"; fi
}

# Points per scan of a sequence: its .bin scans hold 16 bytes a point.
mean_points() {
  local dir=$1/velodyne
  [ -d "$dir" ] || { echo "-"; return; }
  echo $(( $(du -cb "$dir"/*.bin | tail -1 | cut -f1) / 16 / $(ls "$dir" | wc -l) ))
}

# One bench row: elo_run on the CPU (all threads) and on CUDA over INPUT, frame-to-model.
bench_row() {
  local name=$1 input=$2 points=$3
  shift 3
  local cpu cuda cpu_fps cuda_fps bare_fps upload_ms
  cpu=$("$bin/elo_run" --input "$input" --output "$work/p.txt" --quiet --mode f2m --backend cpu "$@" 2>&1)
  cuda=$("$bin/elo_run" --input "$input" --output "$work/p.txt" --quiet --mode f2m --backend cuda "$@" 2>&1) ||
    { fail "bench $name" "$(tail -1 <<<"$cuda")"; return; }
  cpu_fps=$(sed -n 's/^FPS: \([0-9.]*\) (pipeline).*/\1/p' <<<"$cpu")
  cuda_fps=$(sed -n 's/^FPS: \([0-9.]*\) (pipeline).*/\1/p' <<<"$cuda")
  bare_fps=$(sed -n 's/^FPS without the upload: \([0-9.]*\)/\1/p' <<<"$cuda")
  upload_ms=$(awk '/^scan upload to GPU/ {print $5}' <<<"$cuda")
  bench+=("$(printf '%-34s %8s %9s %9s %10s %10s %9s' "$name" "$points" "$cpu_fps" "$cuda_fps" \
    "$(awk -v f="$cuda_fps" 'BEGIN {printf "%.3f", 1000 / f}')" "${bare_fps:--}" "${upload_ms:--}")")
  echo "[$(date +%T)] bench: ${bench[-1]}"
  echo "--- $name, CUDA" >>"$work/bench.log"
  echo "$cuda" >>"$work/bench.log"
}

# elo_run on CUDA over INPUT with the next scan's upload overlapping each scan (the default) and
# without (--no-prefetch): the poses must be identical; the row gives the upload each run waited for.
check_prefetch() {
  local name=$1 input=$2 with without
  with=$("$bin/elo_run" --input "$input" --output "$work/prefetched.txt" --quiet --backend cuda 2>&1) &&
    without=$("$bin/elo_run" --input "$input" --output "$work/unprefetched.txt" --quiet --backend cuda \
      --no-prefetch 2>&1) || { fail "prefetched uploads, $name" "elo_run failed"; return; }
  if ! cmp -s "$work/prefetched.txt" "$work/unprefetched.txt"; then
    fail "prefetched uploads, $name" "poses differ from --no-prefetch"
    return
  fi
  row "prefetched uploads, $name" "poses identical; upload waited $(awk '/^scan upload to GPU/ {print $5}' \
    <<<"$with") ms a scan, $(awk '/^scan upload to GPU/ {print $5}' <<<"$without") ms with --no-prefetch"
}

# The largest difference between two KITTI pose files' translations (entries 4, 8 and 12 of a line), m.
largest_translation_difference() {
  paste -d' ' "$1" "$2" | awk '
    { for (i = 4; i <= 12; i += 4) { d = $i - $(i + 12); if (d < 0) d = -d; if (d > worst) worst = d } }
    END { printf "%.2g", worst + 0 }'
}

# Localization (docs/localization.md) on each backend: a map of the drive (elo_run --map), the drive
# localized in it from the map's origin. The row gives by how much the two backends' poses differ and
# each one's FPS, odometry and map match together.
check_localization() {
  local name=$1 input=$2 map=$work/map.pcd cpu cuda difference
  "$bin/elo_run" --input "$input" --output "$work/p.txt" --quiet --map "$map" >"$work/map.log" 2>&1 ||
    { fail "localization, $name" "elo_run --map failed: $(tail -1 "$work/map.log")"; return; }
  cpu=$("$bin/elo_run" --input "$input" --output "$work/localized_cpu.txt" --quiet --localize "$map" \
    --backend cpu 2>&1) || { fail "localization, $name" "CPU: $(tail -1 <<<"$cpu")"; return; }
  cuda=$("$bin/elo_run" --input "$input" --output "$work/localized_cuda.txt" --quiet --localize "$map" \
    --backend cuda 2>&1) || { fail "localization, $name" "CUDA: $(tail -1 <<<"$cuda")"; return; }
  echo "--- localization, $name, CUDA" >>"$work/bench.log"
  echo "$cuda" >>"$work/bench.log"
  difference=$(largest_translation_difference "$work/localized_cpu.txt" "$work/localized_cuda.txt")
  if awk -v d="$difference" 'BEGIN { exit !(d > 1e-3) }'; then
    fail "localization, $name" "CPU and CUDA poses differ by up to $difference m"
    return
  fi
  row "localization, $name" "CPU and CUDA poses within $difference m; FPS CPU $(fps_with_localization "$cpu"),\
 CUDA $(fps_with_localization "$cuda")"
  for tool in memcheck racecheck initcheck synccheck; do
    check_sanitizer $tool "$(sanitizer_summary $tool)" "5 scans localized" "$input" --localize "$map"
  done
}
# The IMU (docs/imu.md) on each backend: a VLP-16 carried by hand, swung at up to 188 deg/s, its sweeps
# deskewed point by point with a consumer-grade gyro's rotation (the projection's SweepRotation) and its
# accelerometers in the prior. The row gives by how much the two backends' poses differ; the sanitizers
# run over the gyro's deskew kernels.
check_imu() {
  local walk=$work/imu_walk cpu cuda difference imu
  "$bin/elo_sim" --world urban --trajectory curves --frames 150 --seed 11 --sensor vlp16 --gait walk --deskewed 0 \
    --time-convention azimuth --imu consumer --output "$walk" >/dev/null ||
    { fail "IMU walk" "elo_sim failed"; return; }
  imu=(--config "$configs/vlp16.yaml" --config "$walk/imu.yaml" --set deskew.time_source=azimuth)
  cpu=$("$bin/elo_run" --input "$walk" --output "$work/imu_cpu.txt" --quiet --backend cpu "${imu[@]}" 2>&1) ||
    { fail "IMU walk" "CPU: $(tail -1 <<<"$cpu")"; return; }
  cuda=$("$bin/elo_run" --input "$walk" --output "$work/imu_cuda.txt" --quiet --backend cuda "${imu[@]}" 2>&1) ||
    { fail "IMU walk" "CUDA: $(tail -1 <<<"$cuda")"; return; }
  difference=$(largest_translation_difference "$work/imu_cpu.txt" "$work/imu_cuda.txt")
  if awk -v d="$difference" 'BEGIN { exit !(d > 1e-2) }'; then
    fail "IMU walk, VLP-16 swung, 150 scans" "CPU and CUDA poses differ by up to $difference m"
  else
    row "IMU walk, VLP-16 swung, 150 scans" "CPU and CUDA poses within $difference m; FPS CPU\
 $(sed -n 's/^FPS: \([0-9.]*\) (pipeline).*/\1/p' <<<"$cpu"), CUDA $(sed -n 's/^FPS: \([0-9.]*\) (pipeline).*/\1/p' <<<"$cuda")"
  fi
  for tool in memcheck racecheck initcheck synccheck; do
    check_sanitizer $tool "$(sanitizer_summary $tool)" "5 scans, IMU walk" "$walk" "${imu[@]}"
  done
}
sanitizer_summary() { if [ "$1" = racecheck ]; then echo "RACECHECK SUMMARY"; else echo "ERROR SUMMARY"; fi; }
fps_with_localization() { sed -n 's/^FPS with localization: \([0-9.]*\).*/\1/p' <<<"$1"; }

simulate() {  # simulate SENSOR WORLD TRAJECTORY DIR [options]
  local sensor=$1 world=$2 trajectory=$3 dir=$4
  shift 4
  "$bin/elo_sim" --world "$world" --trajectory "$trajectory" --frames "$frames" --seed 7 --sensor "$sensor" \
    --output "$dir" "$@" >/dev/null
}

gpu=$(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null | head -1)
echo "GPU check: ${gpu:-no nvidia-smi}; $(nproc) CPU cores; nvcc $(nvcc --version 2>/dev/null | sed -n 's/.*release \([0-9.]*\).*/\1/p')"
check_agreement
# Localization first after the agreement tests: its map rendering is the newest CUDA code.
simulate hdl64 urban curves "$work/hdl64"
check_localization "HDL-64E, urban, $frames scans" "$work/hdl64"
check_imu
# The real scans deskewed by azimuth, so that every kernel of the odometry runs.
for tool in memcheck racecheck initcheck synccheck; do
  check_sanitizer $tool "$(sanitizer_summary $tool)" "5 real scans" "$scans" --set deskew.time_source=azimuth
done

bench=()
simulate vlp16 urban curves "$work/vlp16"
simulate os1-128 urban curves "$work/os1_128"
simulate hdl64 urban curves "$work/hdl64_distorted" --deskewed 0 --time-convention azimuth
hdl_points=$(mean_points "$work/hdl64")
bench_row "HDL-64E, urban, $frames scans" "$work/hdl64" "$hdl_points"
bench_row "HDL-64E distorted, deskew azimuth" "$work/hdl64_distorted" "$(mean_points "$work/hdl64_distorted")" \
  --set deskew.time_source=azimuth
# Each sensor with its own configuration: under the HDL-64E's defaults the other sensors' beams fall off
# the image and the odometry fails (elo_run warns about the field of view).
bench_row "VLP-16, urban, $frames scans" "$work/vlp16" "$(mean_points "$work/vlp16")" --config "$configs/vlp16.yaml"
bench_row "OS1-128, urban, $frames scans" "$work/os1_128" "$(mean_points "$work/os1_128")" \
  --config "$configs/os1-128.yaml"
[ -d "$scans" ] && bench_row "real HDL-64E, $(ls "$scans" | wc -l) scans" "$scans" "-"
check_prefetch "HDL-64E, urban, $frames scans" "$work/hdl64"

echo
printf '%-44s %s\n' "check" "result"
printf '%s\n' "${rows[@]}"
echo
printf '%-34s %8s %9s %9s %10s %10s %9s\n' "bench, f2m" "points" "CPU FPS" "CUDA FPS" "ms/scan" \
  "w/o upload" "upload ms"
printf '%s\n' "${bench[@]}"
echo "(CPU: all $(nproc) threads. CUDA FPS and ms/scan include the scan's upload; 'upload ms' is what of it the"
echo " frames still waited for, elo_run prefetching each scan while the one before it runs; 'w/o upload' leaves that out.)"
[ -n "${GPU_CHECK_LOG:-}" ] && cp "$work"/*.log "$GPU_CHECK_LOG"/ 2>/dev/null
exit $((failures > 0))
