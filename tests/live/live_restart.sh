#!/usr/bin/env bash
# kill -9 of each stage process during a simulated live run over UDP multicast (launch/sim.launch.yaml,
# real time, in a private network namespace); `adit launch` restarts it. Checks: every killed stage is
# back publishing within 2 s of its restart, resumes from its checkpoint (STATUS: restarted, recovered_*),
# the trajectory never jumps (APE against the simulator's ground truth stays small: a restart at identity
# would be metres off), and the clean stop leaves map.pcd, trajectory.tum and pose_graph.g2o in the run folder.
#   live_restart.sh <bin_dir> <source_dir> [duration_s]
set -euo pipefail
BIN=$1 SRC=$2 DURATION=${3:-40}
if [ -z "${ADIT_IN_NETNS:-}" ]; then
  if [ "$(id -u)" = 0 ]; then NS=(unshare -n); else NS=(unshare -rn); fi
  if ! "${NS[@]}" true 2>/dev/null; then echo "SKIP: cannot make a private network namespace here"; exit 77; fi
  exec "${NS[@]}" env ADIT_IN_NETNS=1 bash "$0" "$@"
fi
ip link set lo up multicast on
ip route add 224.0.0.0/4 dev lo

WORK=$(mktemp -d)
trap '[ -n "${KEEP:-}" ] || rm -rf "$WORK"' EXIT
source "$SRC/tests/integration/time_scale.sh"
"$BIN/adit" launch "$SRC/launch/sim.launch.yaml" --set DURATION="$DURATION" --log-dir "$WORK" --quiet &
LAUNCH=$!
killStage() {  # process name, seconds after start: kill -9 the launcher's child running it
  sleep "$(scaled "$2")"
  local pid
  pid=$(pgrep -P "$LAUNCH" -f "$1" || true)
  if [ -n "$pid" ]; then echo "kill -9 $1 (pid $pid) at ${2}s"; kill -9 "$pid"; else echo "FAIL: no $1 to kill"; fi
}
( killStage adit-odometry 10; killStage adit-mapper 6; killStage adit-loop-closer 8; killStage adit-feature 5 ) &
KILLER=$!
wait "$LAUNCH" || true
wait "$KILLER" || true
RUN=$(ls -d "$WORK"/sim-*)

failed=0
"$BIN/live_report" "$RUN/record.lcmlog" --tum GROUND_TRUTH "$WORK/gt.tum" | tee "$WORK/report.txt"
for p in odometry mapper loop_closer; do
  line=$(grep "^restart $p " "$WORK/report.txt" || true)
  if [ -z "$line" ]; then echo "FAIL: $p did not report a restart on STATUS"; failed=1; continue; fi
  after=$(sed -E 's/.*first_output_after_s=([0-9.]+).*/\1/' <<<"$line")
  if awk -v a="$after" -v l="$(scaled 2)" 'BEGIN { exit !(a <= l) }'; then echo "ok: $p publishing ${after} s after its restart";
  else echo "FAIL: $p took ${after} s to publish after its restart"; failed=1; fi
done
grep -q "recovered_keyframes=[1-9]" "$WORK/report.txt" && echo "ok: loop closer kept its keyframes" ||
  { echo "FAIL: loop closer recovered no keyframes"; failed=1; }
for f in map.pcd trajectory.tum pose_graph.g2o; do
  [ -s "$RUN/$f" ] && echo "ok: $f saved on stop" || { echo "FAIL: no $f in the run folder"; failed=1; }
done
"$BIN/adit" eval --gt "$WORK/gt.tum" --est "$RUN/trajectory.tum" | tee "$WORK/eval.txt" | grep -m1 "all poses"
read -r rmse max < <(awk '/all poses/ { for (i = 1; i <= NF; ++i) { if ($i == "rmse") r = $(i+1); if ($i == "max") m = $(i+1) } print r, m; exit }' "$WORK/eval.txt")
if awk -v r="$rmse" -v m="$max" 'BEGIN { exit !(r < 0.3 && m < 1.0) }'; then echo "ok: APE rmse $rmse m, max $max m";
else echo "FAIL: APE rmse $rmse m, max $max m (a jump)"; failed=1; fi
[ $failed = 0 ] || tail -n 5 "$RUN"/*.log
exit $failed
