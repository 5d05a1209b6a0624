#!/usr/bin/env bash
# Lockstep parity of the live code path: the mapper and the loop closer as real processes (with a run
# folder, checkpoints on, as `adit launch` starts them), each driven from a log of its inputs through
# LCM's file:// provider, produce exactly what `adit replay` produces from the same sensor log: the same
# ODOM_MAPPED stream, and the same map.pcd, trajectory.tum and pose_graph.g2o from the map owner.
#   live_parity.sh <bin_dir>
set -euo pipefail
BIN=$1
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cd "$WORK"
"$BIN/adit" sim --world roadway-loop --duration 20 --seed 3 -o sim.lcmlog --gt gt.tum >/dev/null 2>&1
"$BIN/adit" replay sim.lcmlog -o replay --record-all >/dev/null
# The mapper process on replay's ODOM_SCAN and POSE_GRAPH, then the loop closer process on its ODOM_MAPPED.
"$BIN/adit-mapper" --lcm-url "file://$WORK/replay/output.lcmlog?speed=0" \
  --out-url "file://$WORK/mapper_out.lcmlog?mode=w" --run-dir live 2>&1 | tail -1
"$BIN/adit-loop-closer" --lcm-url "file://$WORK/mapper_out.lcmlog?speed=0" \
  --out-url "file://$WORK/closer_out.lcmlog?mode=w" --run-dir live 2>&1 | tail -2

failed=0
for f in map.pcd trajectory.tum pose_graph.g2o; do
  if cmp -s "replay/$f" "live/$f"; then echo "ok: live/$f is identical to replay's"; else echo "FAIL: live/$f differs from replay's"; failed=1; fi
done
for f in mapper.ckpt loop_closer.ckpt; do
  [ -s "live/$f" ] && echo "ok: $f written" || { echo "FAIL: no live/$f"; failed=1; }
done
"$BIN/live_report" replay/output.lcmlog --tum ODOM_MAPPED replay_mapped.tum >/dev/null
"$BIN/live_report" mapper_out.lcmlog --tum ODOM_MAPPED live_mapped.tum >/dev/null
if cmp -s replay_mapped.tum live_mapped.tum; then echo "ok: ODOM_MAPPED poses identical ($(wc -l < live_mapped.tum) sweeps)";
else echo "FAIL: ODOM_MAPPED poses differ"; failed=1; fi
exit $failed
