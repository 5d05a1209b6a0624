#!/usr/bin/env bash
# The corrected map of a live run (issue 12): the whole pipeline as real processes over UDP multicast in a
# private network namespace, on a small simulated loop at real time. `adit command save_map before_loop`
# is sent before the robot is back at its start; the clean stop saves the map after the loop closed.
# Checks: the early save has no loop in its pose graph and the final one has; the loop closer got the sweeps'
# LinK3D keypoints (FEATURES) and seeded candidates with them; both maps lie on the
# simulator's true surfaces (mean distance of map points to the nearest surface sample, share beyond
# 0.2 m: a ghosted, duplicated roadway shows there) and both trajectories match the ground truth.
#   live_loop_map.sh <bin_dir> <source_dir>   (tests/integration/netns.sh puts it in the namespace)
set -euo pipefail
BIN=$1 SRC=$2
URL="udpm://239.255.76.67:7667?ttl=0"
WORK=$(mktemp -d)
trap '[ -n "${KEEP:-}" ] || rm -rf "$WORK"' EXIT
source "$SRC/tests/integration/time_scale.sh"
"$BIN/adit" sim --config "$SRC/tests/live/small_loop.yaml" --duration 1 -o "$WORK/probe.lcmlog" \
  --world-pcd "$WORK/world.pcd" >/dev/null 2>&1
"$BIN/adit" launch "$SRC/tests/live/loop_map.launch.yaml" --log-dir "$WORK" --quiet &
LAUNCH=$!
sleep "$(scaled 60)"  # sensor time ~59 s: 115 m driven of the 140 m lap, the start not yet in sight
"$BIN/adit" command save_map before_loop --lcm-url "$URL"
wait "$LAUNCH" || true
RUN=$(ls -d "$WORK"/loop-*)
"$BIN/live_report" "$RUN/record.lcmlog" --tum GROUND_TRUTH "$WORK/gt.tum" > "$WORK/report.txt"
grep -E "^(counters loop_closer|latency)" "$WORK/report.txt" || true  # latency: a figure, not asserted

failed=0
loops() { awk '$1 == "EDGE_SE3:QUAT" && $3 - $2 > 1' "$1" | wc -l; }
for f in before_loop.pcd before_loop.tum before_loop.g2o map.pcd trajectory.tum pose_graph.g2o; do
  [ -s "$RUN/$f" ] || { echo "FAIL: no $f in the run folder"; failed=1; }
done
[ $failed = 0 ] || { tail -n 5 "$RUN"/*.log; exit 1; }
before=$(loops "$RUN/before_loop.g2o") after=$(loops "$RUN/pose_graph.g2o")
[ "$before" = 0 ] && echo "ok: no loop in the graph saved before the revisit" ||
  { echo "FAIL: $before loops before the revisit"; failed=1; }
[ "$after" -ge 1 ] && echo "ok: $after loops in the final graph" || { echo "FAIL: no loop closed"; failed=1; }
# FEATURES reach the loop-closer process over the bus: its candidates were seeded by LinK3D keypoints.
seeds=$(grep -E "^counters loop_closer" "$WORK/report.txt" | grep -oE "keypoint_seeds=[0-9]+" | cut -d= -f2)
[ "${seeds:-0}" -ge 1 ] && echo "ok: $seeds loop candidates had a LinK3D keypoint seed" ||
  { echo "FAIL: no LinK3D keypoint seed in the loop closer (keypoint_seeds=${seeds:-missing})"; failed=1; }
check() {  # name map.pcd trajectory.tum
  local line mean far rmse
  line=$("$BIN/map_vs_world" "$2" "$WORK/world.pcd" "$WORK/gt.tum" "$3")
  mean=$(sed -E 's/.*mean_m=([0-9.]+).*/\1/' <<<"$line") far=$(sed -E 's/.*beyond_0.2m=([0-9.]+).*/\1/' <<<"$line")
  rmse=$("$BIN/adit" eval --gt "$WORK/gt.tum" --est "$3" | awk '/all poses/ { for (i = 1; i <= NF; ++i) if ($i == "rmse") print $(i+1); exit }')
  # Bounds: the replayed 105 s drive gives 0.056 m mean, 0.03 % beyond 0.2 m, APE 0.035 m; half the surface
  # sampling spacing (0.05 m) is in the mean. A duplicated roadway puts whole walls beyond 0.2 m.
  if awk -v m="$mean" -v f="$far" -v r="$rmse" 'BEGIN { exit !(m < 0.09 && f < 0.02 && r < 0.15) }'; then
    echo "ok: $1: $line, APE rmse $rmse m"
  else
    echo "FAIL: $1: $line, APE rmse $rmse m"; failed=1
  fi
}
check "map before the loop" "$RUN/before_loop.pcd" "$RUN/before_loop.tum"
check "map after the loop" "$RUN/map.pcd" "$RUN/trajectory.tum"
[ $failed = 0 ] || tail -n 5 "$RUN"/*.log
exit $failed
