#!/usr/bin/env bash
# The corrected map against the simulator's surfaces, before and after loop closure (issue 12, not CI): the
# same simulated drive replayed twice in lockstep, without the loop closer (the mapper's own map: what a live
# run used to save) and with it (the map owner's corrected map, what live runs and `adit replay` save now).
# Prints, for each map, the mean distance of its points to the nearest true surface and the share farther
# than 0.2 m (a ghosted, duplicated roadway shows there), and the APE of each trajectory.
#   scripts/map_accuracy.sh [DURATION_S=500] [WORLD=roadway-loop]
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=$ROOT/build/bin
DURATION=${1:-500} WORLD=${2:-roadway-loop}
OUT=$ROOT/logs/map-accuracy
rm -rf "$OUT"
mkdir -p "$OUT"
cd "$OUT"
"$BIN/adit" sim --world "$WORLD" --duration "$DURATION" --seed 1 -o sim.lcmlog --gt gt.tum --world-pcd world.pcd >/dev/null 2>&1
"$BIN/adit" replay sim.lcmlog -o before --stages feature odometry mapper --record '^$' >/dev/null
"$BIN/adit" replay sim.lcmlog -o after --record '^$' >/dev/null
loops=$(awk '$1 == "EDGE_SE3:QUAT" && $3 - $2 > 1' after/pose_graph.g2o | wc -l)
for run in before after; do
  ape=$("$BIN/adit" eval --gt gt.tum --est $run/trajectory.tum | awk '/all poses/ { for (i = 1; i <= NF; ++i) if ($i == "rmse") print $(i+1); exit }')
  echo "$run loop closure: APE rmse $ape m, map $("$BIN/map_vs_world" $run/map.pcd world.pcd gt.tum $run/trajectory.tum)"
done
echo "($WORLD, $DURATION s, $loops loop edges in the graph)"
rm -f sim.lcmlog
