#!/usr/bin/env bash
# Live-run figures (issue 12), not a CI test: launch/sim.launch.yaml at real time over UDP multicast in a
# private network namespace, twice on the same simulated drive:
#   A  undisturbed: APE of the live trajectory, APE of `adit replay` on A's recorded sensor log (live vs
#      lockstep), MAP_UPDATE bandwidth, map against the simulator's surfaces;
#   B  each stage process killed once with SIGKILL (odometry, mapper, loop closer, feature, evenly spaced),
#      restarted by `adit launch`: APE relative to A, map against the surfaces (a duplicated roadway shows
#      as points far from every surface).
#   scripts/live_benchmark.sh [DURATION_S=300] [WORLD=roadway-loop]
# Needs a build (build/bin). Writes its figures to stdout and keeps the runs in logs/live-benchmark/.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=$ROOT/build/bin
DURATION=${1:-300} WORLD=${2:-roadway-loop}
if [ -z "${ADIT_IN_NETNS:-}" ]; then
  if [ "$(id -u)" = 0 ]; then NS=(unshare -n); else NS=(unshare -rn); fi
  exec "${NS[@]}" env ADIT_IN_NETNS=1 bash "$0" "$@"
fi
ip link set lo up multicast on
ip route add 224.0.0.0/4 dev lo
OUT=$ROOT/logs/live-benchmark
rm -rf "$OUT"
mkdir -p "$OUT"
"$BIN/adit" sim --world "$WORLD" --duration 1 --seed 1 -o "$OUT/probe.lcmlog" --world-pcd "$OUT/world.pcd" >/dev/null 2>&1

ape() {  # gt est -> "rmse max"
  "$BIN/adit" eval --gt "$1" --est "$2" |
    awk '/all poses/ { for (i = 1; i <= NF; ++i) { if ($i == "rmse") r = $(i+1); if ($i == "max") m = $(i+1) } print r, m; exit }'
}

run() {  # name, kill spacing (0 = none)
  local name=$1 spacing=$2 dir launch killer=""
  dir=$OUT/$name
  mkdir -p "$dir"
  "$BIN/adit" launch "$ROOT/launch/sim.launch.yaml" --set DURATION="$DURATION" --set WORLD="$WORLD" \
    --log-dir "$dir" --quiet > "$dir/launch.txt" 2>&1 &
  launch=$!
  if [ "$spacing" -gt 0 ]; then
    (
      for p in adit-odometry adit-mapper adit-loop-closer adit-feature; do
        sleep "$spacing"
        pid=$(pgrep -P "$launch" -f "$p" || true)
        [ -n "$pid" ] && kill -9 "$pid" && echo "killed $p at +${spacing}s" >> "$dir/kills.txt"
      done
    ) &
    killer=$!
  fi
  wait "$launch" || true
  [ -n "$killer" ] && wait "$killer" || true
  local run
  run=$(ls -d "$dir"/sim-*)
  "$BIN/live_report" "$run/record.lcmlog" --tum GROUND_TRUTH "$dir/gt.tum" --sensors "$dir/sensors.lcmlog" > "$dir/report.txt"
  echo "$run"
}

loops() {  # report.txt -> loops the live loop closer accepted (its last STATUS)
  awk '$1 == "counters" && $2 == "loop_closer" { for (i = 3; i <= NF; ++i) if ($i ~ /^loops_accepted=/) { sub(/.*=/, "", $i); n = $i } } END { print n + 0 }' "$1"
}

RUN_A=$(run undisturbed 0)
read -r A_RMSE A_MAX < <(ape "$OUT/undisturbed/gt.tum" "$RUN_A/trajectory.tum")
RUN_B=$(run killed $((DURATION / 5)))
read -r B_RMSE B_MAX < <(ape "$OUT/killed/gt.tum" "$RUN_B/trajectory.tum")
"$BIN/adit" replay "$OUT/undisturbed/sensors.lcmlog" -o "$OUT/undisturbed/replay" --record '^$' >/dev/null
read -r R_RMSE R_MAX < <(ape "$OUT/undisturbed/gt.tum" "$OUT/undisturbed/replay/trajectory.tum")

echo "live runs: $WORLD, $DURATION s, vlp16, real time over UDP multicast"
echo "  A live (undisturbed)      APE rmse $A_RMSE m, max $A_MAX m"
echo "  A adit replay of its log  APE rmse $R_RMSE m, max $R_MAX m"
echo "  B each stage killed once  APE rmse $B_RMSE m, max $B_MAX m ($(awk -v a="$A_RMSE" -v b="$B_RMSE" 'BEGIN { printf "%+.0f %%", (b / a - 1) * 100 }') vs A)"
echo "  B restarts:"; grep "^restart" "$OUT/killed/report.txt" | sed 's/^/    /'
echo "  loops accepted: A $(loops "$OUT/undisturbed/report.txt"), B $(loops "$OUT/killed/report.txt") (B's loop closer was killed before them: they close against recovered keyframes), replay $(awk '$1 == "EDGE_SE3:QUAT" && $3 - $2 > 1' "$OUT/undisturbed/replay/pose_graph.g2o" | wc -l)"
echo "  $(grep "^latency" "$OUT/undisturbed/report.txt") (A; B: $(grep "^latency" "$OUT/killed/report.txt" | cut -d" " -f3-))"
echo "  MAP_UPDATE (A): $(grep "^map_update" "$OUT/undisturbed/report.txt")"
echo "  sweeps reaching the map owner: A $(wc -l < "$RUN_A/trajectory.tum"), B $(wc -l < "$RUN_B/trajectory.tum"), replay $(wc -l < "$OUT/undisturbed/replay/trajectory.tum")"
echo "  map vs world A live:   $("$BIN/map_vs_world" "$RUN_A/map.pcd" "$OUT/world.pcd" "$OUT/undisturbed/gt.tum" "$RUN_A/trajectory.tum")"
echo "  map vs world A replay: $("$BIN/map_vs_world" "$OUT/undisturbed/replay/map.pcd" "$OUT/world.pcd" "$OUT/undisturbed/gt.tum" "$OUT/undisturbed/replay/trajectory.tum")"
echo "  map vs world B:        $("$BIN/map_vs_world" "$RUN_B/map.pcd" "$OUT/world.pcd" "$OUT/killed/gt.tum" "$RUN_B/trajectory.tum")"
