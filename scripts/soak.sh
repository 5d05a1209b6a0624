#!/usr/bin/env bash
# Soak benchmark (not a CI test): the simulated live run (launch/sim.launch.yaml: simulator + four stage
# processes + recorder) for a long time in a private network namespace, sampling the resident memory, peak
# memory, threads and open file descriptors of every process, to show that nothing grows without bound.
#   scripts/soak.sh [--duration S] [--world W] [--interval S] [--rate R] [-o DIR]
# Defaults: 7200 s (2 hours), roadway-loop, a sample every 10 s, output in logs/soak-<time>/. --rate R simulates
# at R times real time (the stages keep up with 2 on a quiet 2-core machine): DURATION seconds of sensor time in
# DURATION / R of wall time. Writes samples.csv (t_s,process,pid,rss_mb,hwm_mb,threads,fds,anon_mb; t_s in
# seconds of sensor time, i.e. wall seconds x R) and prints a summary per process: peak RSS (VmHWM),
# RSS at 5 minutes and at the end, growth after the first 5 minutes in MB per hour, fds and threads min/max,
# restarts (pid changes), and the anonymous memory's floor (RssAnon: the heap, stacks and arenas, not the
# library code a process pages in when it first runs a path) in the first and the last 10 minutes of driving
# (5-15 min and DURATION-10 min to DURATION: the lowest sample of each, so a loop job's transient peak or a
# heap not yet trimmed does not count as growth), with the growth per hour between them.
# `scripts/soak.sh [--duration S] --summary samples.csv` prints the summary of an earlier run.
# Only STATUS is recorded (the sensor data would be ~6 MB/s). Run it niced on a shared machine.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
summarise() {  # samples.csv -> one line per process; DURATION sets the last window of the anonymous floor
  awk -F, -v D="$DURATION" 'NR > 1 {
    k = $2; if (!(k in n)) { order[++m] = k }
    n[k]++; last[k] = $4; lastt[k] = $1
    if ($1 <= 300) at5[k] = $4
    if ($1 >= 300) { if (!(k in t5)) { t5[k] = $1; r5[k] = $4 } }
    if (!(k in fmin) || $7 < fmin[k]) fmin[k] = $7; if ($7 > fmax[k]) fmax[k] = $7
    if (!(k in tmin) || $6 < tmin[k]) tmin[k] = $6; if ($6 > tmax[k]) tmax[k] = $6
    if (!(k in pid)) pid[k] = $3; else if ($3 != pid[k]) { restarts[k]++; pid[k] = $3 }
    if ($5 > hwm[k]) hwm[k] = $5
    if (NF >= 8 && $1 >= 300 && $1 < 900 && (!(k in a0) || $8 < a0[k])) a0[k] = $8
    if (NF >= 8 && $1 >= D - 600 && $1 < D && (!(k in a1) || $8 < a1[k])) a1[k] = $8
  }
  END {
    printf "%-18s %8s %9s %9s %9s %12s %9s %9s %8s %15s %11s\n", "process", "samples", "peak_MB", "5min_MB", "end_MB", "MB/h_after5", "fds", "threads", "restarts", "anon_floor_MB", "anon_MB/h"
    for (i = 1; i <= m; ++i) { k = order[i]
      g = (k in t5 && lastt[k] > t5[k]) ? (last[k] - r5[k]) / ((lastt[k] - t5[k]) / 3600) : 0
      floor = (k in a0 && k in a1) ? sprintf("%.1f -> %.1f", a0[k], a1[k]) : "-"
      ag = (k in a0 && k in a1 && D > 1500) ? sprintf("%.2f", (a1[k] - a0[k]) / ((D - 1200) / 3600)) : "-"
      printf "%-18s %8d %9.1f %9.1f %9.1f %12.1f %4d-%-4d %4d-%-4d %8d %15s %11s\n", k, n[k], hwm[k], r5[k], last[k], g, fmin[k], fmax[k], tmin[k], tmax[k], restarts[k] + 0, floor, ag }
  }' "$1"
}
DURATION=7200 WORLD=roadway-loop INTERVAL=10 RATE=1 OUT=
while [ $# -gt 0 ]; do
  case $1 in
    --duration) DURATION=$2; shift 2 ;;
    --world) WORLD=$2; shift 2 ;;
    --interval) INTERVAL=$2; shift 2 ;;
    --rate) RATE=$2; shift 2 ;;
    -o) OUT=$2; shift 2 ;;
    --summary) summarise "$2"; exit 0 ;;
    *) echo "usage: scripts/soak.sh [--duration S] [--world W] [--interval S] [--rate R] [-o DIR]" >&2; exit 2 ;;
  esac
done
OUT=${OUT:-$ROOT/logs/soak-$(date +%Y%m%d-%H%M%S)}
if [ -z "${ADIT_IN_NETNS:-}" ]; then
  mkdir -p "$OUT"
  exec bash "$ROOT/tests/integration/netns.sh" bash "$0" --duration "$DURATION" --world "$WORLD" --interval "$INTERVAL" --rate "$RATE" -o "$OUT"
fi
BIN=$ROOT/build/bin
"$BIN/adit" launch "$ROOT/launch/sim.launch.yaml" --set WORLD="$WORLD" --set DURATION="$DURATION" --set RATE="$RATE" \
  --set 'RECORD=^STATUS_.*$' --log-dir "$OUT" --quiet > "$OUT/launch.out" 2>&1 &
LAUNCH=$!
trap 'kill -INT $LAUNCH 2>/dev/null || true' INT TERM
echo "soak: $WORLD for $DURATION s of sensor time at ${RATE}x real time, a sample every $INTERVAL s, output in $OUT"
echo "t_s,process,pid,rss_mb,hwm_mb,threads,fds,anon_mb" > "$OUT/samples.csv"
start=$SECONDS
sample() {  # every live child of the launcher
  local t pid comm
  t=$(awk -v s=$((SECONDS - start)) -v r="$RATE" 'BEGIN { printf "%d", s * r }')
  for pid in $(cat /proc/$LAUNCH/task/*/children 2>/dev/null); do
    [ -r "/proc/$pid/status" ] || continue
    comm=$(cat "/proc/$pid/comm" 2>/dev/null) || continue
    awk -v t="$t" -v c="$comm" -v p="$pid" -v fds="$(ls "/proc/$pid/fd" 2>/dev/null | wc -l)" '
      /^VmRSS:/ { rss = $2 / 1024 } /^VmHWM:/ { hwm = $2 / 1024 } /^Threads:/ { th = $2 } /^RssAnon:/ { anon = $2 / 1024 }
      END { printf "%d,%s,%s,%.1f,%.1f,%d,%d,%.1f\n", t, c, p, rss, hwm, th, fds, anon }' "/proc/$pid/status" >> "$OUT/samples.csv"
  done
}
while kill -0 $LAUNCH 2>/dev/null; do
  sample
  sleep "$INTERVAL"
done
rc=0
wait $LAUNCH || rc=$?
tail -1 "$OUT/launch.out"
echo "soak ran $((SECONDS - start)) s; adit launch exit code $rc"
summarise "$OUT/samples.csv" | tee "$OUT/summary.txt"
