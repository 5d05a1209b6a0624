#!/usr/bin/env bash
# Disk full while recording: the run folder is a 2 MB tmpfs (own mount namespace). The recorder fails, the
# launcher says the disk is full, restarts it with back-off (never in a tight loop; each restart writes a new
# record.N.lcmlog, never over the old one), gives up after record_max_restarts (3) and ends with exit code 2
# and the reason; the pipeline runs on undisturbed to the end.
#   disk_full.sh <bin_dir> <source_dir>
NETNS_FLAGS=--mount
source "$(dirname "$0")/common.sh" "$@"
DURATION=30
mkdir -p "$WORK/logs"
if ! mount -t tmpfs -o size=2m adit-full "$WORK/logs" 2>"$WORK/mount.err"; then
  echo "SKIP: cannot mount a tmpfs in the test's mount namespace: $(cat "$WORK/mount.err")"
  exit 77
fi
trap 'umount "$WORK/logs" 2>/dev/null || true; cleanup' EXIT
OUT=$WORK/launch.out
start_launch "$OUT" "$FAULTS/disk_full.launch.yaml" --set DURATION=$DURATION --set WITNESS="$WORK/witness.lcmlog" \
  --log-dir "$WORK/logs" --quiet
wait_launch
grep -E '^\[launch\]' "$OUT"
"$BIN/fault-facts" "$WORK/witness.lcmlog" > "$WORK/facts.txt"
grep -E '^(outputs|restarted|status_gap_s)' "$WORK/facts.txt"

expect "adit launch exit code" "$LAUNCH_RC" == 2
expect_grep "the launcher says the disk is full" "recorder .*the run folder's disk is full" "$OUT"
expect_grep "the last line says the recorder gave up" 'run failed.*recorder gave up' <(tail -1 "$OUT")
starts=$(grep -c 'started recorder' "$OUT")
expect "recorder starts (1 + at most record_max_restarts)" "$starts" "<=" 4
expect_grep "back-off between recorder restarts (1 s, 2 s, 4 s)" 'recorder .*restarting in 4 s' "$OUT"
expect "recorded files kept (record.lcmlog not overwritten by a restart)" "$(ls "$(run_dir)" | grep -c '^record.*lcmlog$')" == "$starts"
expect "feature process restarts" "$(fact "$WORK/facts.txt" restarted STATUS_FEATURE)" == 0
expect "odometry process restarts" "$(fact "$WORK/facts.txt" restarted STATUS_ODOMETRY)" == 0
expect "FEATURES published (of $((DURATION * 10)) sweeps)" "$(fact "$WORK/facts.txt" outputs STATUS_FEATURE)" ">=" $((DURATION * 8))
expect "ODOM_SCAN published" "$(fact "$WORK/facts.txt" outputs STATUS_ODOMETRY)" ">=" $((DURATION * 8))
expect "longest silence of STATUS_ODOMETRY (s)" "$(fact "$WORK/facts.txt" status_gap_s STATUS_ODOMETRY)" "<" 5
echo "figure: recorder on a full 2 MB disk: $starts starts in all, given up; pipeline published $(fact "$WORK/facts.txt" outputs STATUS_ODOMETRY) ODOM_SCAN of $((DURATION * 10)) sweeps"
exit $failed
