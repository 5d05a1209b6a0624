#!/usr/bin/env bash
# Accuracy of the registration stages in one table (issue 15: a speed-up must not cost accuracy; rerun it
# before and after a change to odometry, mapping or the loop verifier and compare the two tables).
# Rows: the simulated roadway-loop (120 s, seed 1) through `adit replay` with every stage (trajectory.tum and
# odometry.tum, the mapper's poses before loop correction) and without the loop closer; kitti_mini 00, 01, 02
# through `adit replay` with launch/sensors/hdl64.yaml. Scan-to-scan odometry alone is judged by the tests
# odometry_kitti and odometry_sim (relative pose error per frame pair, drift over a simulated drive).
# Figures: APE rmse (se3 alignment) in metres, and the CPU seconds of each replay (user+sys).
#   scripts/accuracy_check.sh [BIN_DIR=build/bin] [KITTI_MINI=../shared/data/kitti_mini]
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=$(cd "${1:-$ROOT/build/bin}" && pwd)
KITTI=$(cd "${2:-$ROOT/../shared/data/kitti_mini}" && pwd)
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
cd "$OUT"

rmse() {  # rmse of `adit eval` over all poses
  "$BIN/adit" eval "$@" | awk '/all poses/ { for (i = 1; i <= NF; ++i) if ($i == "rmse") print $(i+1); exit }'
}
replay() {  # replay LOG OUT [args...]: prints the CPU seconds
  local log=$1 out=$2; shift 2
  /usr/bin/time -f '%U %S' -o "$out.time" "$BIN/adit" replay "$log" -o "$out" --no-progress --record '^$' "$@" >/dev/null
  awk '{ printf "%.1f", $1 + $2 }' "$out.time"
}

printf '%-38s %12s %10s\n' "run" "APE rmse m" "CPU s"
"$BIN/adit" sim --world roadway-loop --duration 120 --seed 1 -o sim.lcmlog --gt gt.tum >/dev/null 2>&1
cpu=$(replay sim.lcmlog full)
printf '%-38s %12s %10s\n' "roadway-loop 120 s, all stages" "$(rmse --gt gt.tum --est full/trajectory.tum)" "$cpu"
printf '%-38s %12s %10s\n' "roadway-loop, before loop correction" "$(rmse --gt gt.tum --est full/odometry.tum)" "-"
cpu=$(replay sim.lcmlog noloop --stages feature odometry mapper)
printf '%-38s %12s %10s\n' "roadway-loop, no loop closure" "$(rmse --gt gt.tum --est noloop/trajectory.tum)" "$cpu"
for seq in 00 01 02; do
  "$BIN/adit" import kitti "$KITTI/sequences/$seq" -o "k$seq.lcmlog" >/dev/null 2>&1
  cpu=$(replay "k$seq.lcmlog" "k$seq" --config "$ROOT/launch/sensors/hdl64.yaml")
  ape=$(rmse --gt "$KITTI/poses/$seq.txt" --calib "$KITTI/sequences/$seq/calib.txt" \
    --gt-times "$KITTI/sequences/$seq/times.txt" --est "k$seq/trajectory.tum")
  printf '%-38s %12s %10s\n' "kitti_mini $seq, all stages" "$ape" "$cpu"
done
