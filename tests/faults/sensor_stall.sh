#!/usr/bin/env bash
# A stalled sensor: the lidar stream stops for 10 s and comes back, later the IMU alone for 10 s. The stages
# count the gap (lost_input from the sequence numbers, time_jump), nothing restarts or stalls, the run goes
# on to the end, and the mapped trajectory does not jump: the motion between consecutive ODOM_MAPPED poses
# (across the gap too) matches the true motion.
#   sensor_stall.sh <bin_dir> <source_dir>
source "$(dirname "$0")/common.sh" "$@"
DURATION=50
OUT=$WORK/launch.out
start_launch "$OUT" "$FAULTS/sensor_stall.launch.yaml" --set DURATION=$DURATION --set LIDAR_STALL=12:10 \
  --set IMU_STALL=30:10 --log-dir "$WORK/logs" --quiet
wait_launch
grep -E '^\[launch\]' "$OUT"
RUN=$(run_dir)
mapfile -t series < <(record_series "$RUN")
"$BIN/fault-facts" --out "$WORK" "${series[@]}" > "$WORK/facts.txt"
cat "$WORK/facts.txt" | grep -vE '^counter .* (p50|p95)' || true
"$BIN/adit" eval --gt "$WORK/truth.tum" --est "$WORK/mapped.tum" --align se3 | tee "$WORK/eval.txt" | head -12

sweeps=$((DURATION * 10 - 100))
expect "adit launch exit code" "$LAUNCH_RC" == 0
expect "lost_input on LIDAR_POINTS at the feature stage (sweeps not sent in the 10 s stall)" \
  "$(fact "$WORK/facts.txt" counter STATUS_FEATURE lost_input)" ">=" 99
expect "time_jump counted by the feature stage" "$(fact "$WORK/facts.txt" counter STATUS_FEATURE time_jump)" ">=" 2
expect "time_jump counted by the odometry" "$(fact "$WORK/facts.txt" counter STATUS_ODOMETRY time_jump)" ">=" 2
for p in FEATURE ODOMETRY MAPPER; do
  expect "STATUS_$p restarts" "$(fact "$WORK/facts.txt" restarted STATUS_$p)" == 0
done
expect "ODOM_MAPPED poses (of $sweeps sweeps sent)" "$(fact "$WORK/facts.txt" messages ODOM_MAPPED)" ">=" $((sweeps * 9 / 10))
expect "largest pose jump: |estimated - true motion| between consecutive ODOM_MAPPED (m)" \
  "$(fact "$WORK/facts.txt" jump_m)" "<" "${MAX_JUMP_M:-0.5}"
# Without IMU (its 10 s stall) the per-sweep rotation is that of the motion model alone: up to 2.9 deg off
# between consecutive sweeps, as in a whole run without IMU (0.6 deg with it); not a jump of the trajectory.
expect "largest rotation error between consecutive poses (deg)" "$(fact "$WORK/facts.txt" jump_deg)" "<" 5
echo "figure: lidar stalled 10 s, IMU stalled 10 s: largest jump $(fact "$WORK/facts.txt" jump_m) m / $(fact "$WORK/facts.txt" jump_deg) deg at $(fact "$WORK/facts.txt" jump_at_s) s; APE rmse $(awk '/all poses/ { for (i = 1; i <= NF; ++i) if ($i == "rmse") print $(i + 1) }' "$WORK/eval.txt") m"
exit $failed
