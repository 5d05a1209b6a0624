#!/usr/bin/env bash
# Build the libFuzzer harnesses of tests/fuzz with Debian's clang (AddressSanitizer + UndefinedBehaviorSanitizer)
# into build-fuzz/, and run them one at a time at the lowest CPU priority.
#
#   scripts/fuzz.sh [HARNESS...] [--seconds N] [--build-only | --no-build]
#
# HARNESS: pcd kitti lcmlog imu_text config launch_file lidar_packets n100_serial node_messages pcap rosbag web_server
# map_bundle view_messages (default: all).
# Each runs N seconds (default 60) from its seed corpus (tests/fuzz/corpus/<harness>, copied: the repository's
# corpus is not changed); inputs it finds interesting stay in build-fuzz/corpus/<harness>, crashes go to
# build-fuzz/findings/<harness>/. Prints per harness: executions, coverage (cov: edges, ft: features), findings.
# A finding: fix it, then add its input to tests/fuzz/regressions/<harness>/ (replayed by ctest fuzz_regressions).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
BUILD=$ROOT/build-fuzz
SECONDS_EACH=60
BUILD_ONLY=0
NO_BUILD=0
ALL=(pcd kitti lcmlog imu_text config launch_file lidar_packets n100_serial node_messages pcap rosbag web_server map_bundle
     view_messages)
HARNESSES=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --seconds) SECONDS_EACH=$2; shift 2 ;;
    --build-only) BUILD_ONLY=1; shift ;;
    --no-build) NO_BUILD=1; shift ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    -*) echo "fuzz.sh: unknown option $1" >&2; exit 2 ;;
    *) HARNESSES+=("$1"); shift ;;
  esac
done
[[ ${#HARNESSES[@]} -eq 0 ]] && HARNESSES=("${ALL[@]}")

command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (apt-get install clang)" >&2; exit 1; }
SAN="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer"
if [[ ! -f $BUILD/CMakeCache.txt ]]; then
  cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DADIT_STRICT=ON \
    -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DCMAKE_CXX_FLAGS="$SAN" -DCMAKE_C_FLAGS="$SAN" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
    $(command -v ccache >/dev/null && echo -DCMAKE_CXX_COMPILER_LAUNCHER=ccache) >/dev/null
fi
targets=()
for h in "${HARNESSES[@]}"; do targets+=("fuzz_$h"); done
[[ $NO_BUILD -eq 1 ]] || nice -n 19 cmake --build "$BUILD" -j2 --target "${targets[@]}"
[[ $BUILD_ONLY -eq 1 ]] && exit 0

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
declare -A MAX_LEN=([pcap]=20000 [rosbag]=20000 [lidar_packets]=20000 [node_messages]=100000 [kitti]=20000 [pcd]=20000 [lcmlog]=20000
  [map_bundle]=40000 [web_server]=8192 [view_messages]=100000)
summary=()
status=0
for h in "${HARNESSES[@]}"; do
  corpus=$BUILD/corpus/$h findings=$BUILD/findings/$h log=$BUILD/logs/$h.log
  mkdir -p "$corpus" "$findings" "$(dirname "$log")"
  cp -n "$ROOT/tests/fuzz/corpus/$h"/* "$corpus"/ 2>/dev/null || true
  before=$(ls "$findings" | wc -l)
  echo "== $h: ${SECONDS_EACH} s" >&2
  set +e
  started=$(date +%s)
  nice -n 19 "$BUILD/bin/fuzz_$h" "$corpus" -max_total_time="$SECONDS_EACH" -max_len="${MAX_LEN[$h]:-4096}" \
    -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024 -print_final_stats=1 -artifact_prefix="$findings/" \
    >"$log" 2>&1
  rc=$?
  elapsed=$(( $(date +%s) - started ))
  set -e
  execs=$(grep -o 'stat::number_of_executed_units: [0-9]*' "$log" | grep -o '[0-9]*$' | tail -1)
  cov=$(grep -o 'cov: [0-9]* ft: [0-9]*' "$log" | tail -1)
  found=$(( $(ls "$findings" | wc -l) - before ))
  [[ $rc -ne 0 || $found -ne 0 ]] && status=1
  summary+=("$(printf '%-14s %6s s  %10s execs  %-20s findings %d%s' "$h" "$elapsed" "${execs:-?}" "${cov:-cov: ?}" \
    "$found" "$([[ $rc -ne 0 ]] && echo "  (exit $rc, see $log)")")")
done
printf '%s\n' "${summary[@]}"
exit $status
