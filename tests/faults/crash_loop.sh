#!/usr/bin/env bash
# Repeated crashes: `adit launch` restarts a process killed with SIGKILL with back-off (1 s, 2 s), tells it it
# is a restart (ADIT_RESTART_COUNT, ADIT_RUN_DIR), gives up at the 3rd exit within the window with a clear
# message, and the other processes are not disturbed (they keep running and publishing STATUS and FEATURES).
# A killed recorder comes back writing record.1.lcmlog and record.lcmlog keeps what it had. The launcher
# exits 2 and says why in its last line.
#   crash_loop.sh <bin_dir> <source_dir>
source "$(dirname "$0")/common.sh" "$@"
DURATION=40
OUT=$WORK/launch.out
start_launch "$OUT" "$FAULTS/crash_loop.launch.yaml" --set DURATION=$DURATION --log-dir "$WORK/logs"
pid_of() { sed -E 's/.*\(pid ([0-9]+).*/\1/' <<< "$1"; }

wait_line "$OUT" 'started sim' 60 > /dev/null
sleep 5
kill -KILL "$(pid_of "$(wait_line "$OUT" 'started recorder' 5)")"
wait_line "$OUT" 'started recorder \(pid [0-9]+, restart 1' 20
for k in 1 2 3; do
  line=$(grep -E 'started odometry' "$OUT" | tail -1)
  echo "killing: $line"
  kill -KILL "$(pid_of "$line")"
  if [ $k -lt 3 ]; then
    line=$(wait_line "$OUT" "started odometry \\(pid [0-9]+, restart $k\\)" 30)
    if [ $k = 1 ]; then  # what the restarted process was told
      env_of=$(tr '\0' '\n' < "/proc/$(pid_of "$line")/environ" | grep -E '^ADIT_(RESTART_COUNT|RUN_DIR|PROCESS_NAME)=' | sort | tr '\n' ' ')
      echo "environment of the restarted odometry: $env_of"
      grep -q 'ADIT_RESTART_COUNT=1 ' <<< "$env_of" && grep -q 'ADIT_RUN_DIR=/' <<< "$env_of" \
        || { echo "FAIL: ADIT_RESTART_COUNT=1 / ADIT_RUN_DIR not in the restarted process's environment"; failed=1; }
    fi
    sleep 2
  fi
done
wait_line "$OUT" 'odometry gave up' 20
wait_launch
grep -E '^\[launch\]' "$OUT"

RUN=$(run_dir)
mapfile -t series < <(record_series "$RUN")
"$BIN/fault-facts" "${series[@]}" > "$WORK/facts.txt"
cat "$WORK/facts.txt" | grep -E '^(messages|outputs|restarted|status_gap_s|inputs)'
expect "adit launch exit code" "$LAUNCH_RC" == 2
expect_grep "the last line says the run failed because the odometry gave up" 'run failed.*odometry gave up: 3 exits within 60 s' <(tail -1 "$OUT")
expect_grep "back-off 1 s after the 1st kill" 'odometry killed by signal Killed: restarting in 1 s' "$OUT"
expect_grep "back-off 2 s after the 2nd kill" 'odometry killed by signal Killed: restarting in 2 s' "$OUT"
expect "recorder files in the series" "${#series[@]}" == 2
expect "STATUS messages kept in record.lcmlog (before the recorder was killed)" \
  "$("$BIN/fault-facts" "$RUN/record.lcmlog" | awk '$1 == "messages" && $2 ~ /^STATUS_/ { n += $3 } END { print n + 0 }')" ">=" 5
cat "${series[@]}" > "$WORK/all.lcmlog"  # the series concatenated is one log (README)
"$BIN/adit" info "$WORK/all.lcmlog" > "$WORK/info.txt"
expect "STATUS_FEATURE in the concatenated series, by adit info" \
  "$(awk '$1 == "STATUS_FEATURE" { print $2 }' "$WORK/info.txt")" == "$(fact "$WORK/facts.txt" messages STATUS_FEATURE)"
expect "feature process restarts" "$(fact "$WORK/facts.txt" restarted STATUS_FEATURE)" == 0
expect "simulator restarts" "$(fact "$WORK/facts.txt" restarted STATUS_SIM)" == 0
expect "longest silence of STATUS_FEATURE (s; includes the recorder's own 1 s restart)" \
  "$(fact "$WORK/facts.txt" status_gap_s STATUS_FEATURE)" "<" 6
expect "FEATURES published by the feature process (of $((DURATION * 10)) sweeps)" \
  "$(fact "$WORK/facts.txt" outputs STATUS_FEATURE)" ">=" $((DURATION * 10 * 8 / 10))
expect "odometry restarts seen on its STATUS" "$(fact "$WORK/facts.txt" restarted STATUS_ODOMETRY)" ">=" 1
echo "figure: odometry killed 3 times with SIGKILL: restarted after 1 s and 2 s, given up at the 3rd exit; feature and simulator undisturbed"
exit $failed
