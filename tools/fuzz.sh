#!/usr/bin/env bash
# Runs each libFuzzer target of test/fuzz for a bounded time (make fuzz). Usage:
#   tools/fuzz.sh BUILD_DIR SECONDS_PER_TARGET TARGET...
# A target starts from the committed seeds (test/fuzz/corpus/TARGET) and past crashers
# (test/fuzz/regressions/TARGET), which it only reads; the inputs it finds go to
# BUILD_DIR/fuzz/corpus/TARGET and carry over to the next run. A crash, a leak, a sanitizer report, a
# violated property, an input slower than 10 s or an allocation over 2 GB stops the target, leaves the
# input in BUILD_DIR/fuzz/crashers/TARGET/ and fails the run (after the other targets ran). Fix the code,
# then move the input into test/fuzz/regressions/TARGET/, where every ctest run replays it.
set -euo pipefail
build=$(realpath "$1")
seconds=$2
shift 2
source_dir=$(cd "$(dirname "$0")/.." && pwd)
fuzz_dir="$source_dir/test/fuzz"

failed=()
for target in "$@"; do
  corpus="$build/fuzz/corpus/$target"
  crashers="$build/fuzz/crashers/$target"
  log="$build/fuzz/$target.log"
  mkdir -p "$corpus" "$crashers"
  inputs=("$corpus" "$fuzz_dir/corpus/$target")
  [ -d "$fuzz_dir/regressions/$target" ] && inputs+=("$fuzz_dir/regressions/$target")
  options=(-max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048
           -print_final_stats=1 -artifact_prefix="$crashers/")
  [ -f "$fuzz_dir/$target.dict" ] && options+=(-dict="$fuzz_dir/$target.dict")
  echo "=== $target: $seconds s (log: $log)"
  if "$build/devel/lib/elo_odometry/$target" "${options[@]}" "${inputs[@]}" >"$log" 2>&1; then
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
    coverage=$(grep -o 'cov: [0-9]* ft: [0-9]* corp: [0-9]*' "$log" | tail -1)
    echo "$target: $runs inputs, $coverage, nothing found"
  else
    # The report, from its first line (a sanitizer's, an uncaught exception's or a property's) on.
    grep -m1 -A30 -E 'ERROR: |runtime error|terminate called|fuzz property violated' "$log" || tail -n 30 "$log"
    echo "$target: FAILED; the input is in $crashers/" >&2
    failed+=("$target")
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: failed: ${failed[*]}" >&2
  exit 1
fi
