# Shared by the fault tests (source it: `source "$(dirname "$0")/common.sh" "$@"`; arguments BIN_DIR ROOT).
# Re-runs the calling script inside a private network namespace (netns.sh; exit 77 = skipped with the reason),
# makes a work folder, and offers: launch runs in the background, waiting for a launcher line, facts from the
# recorded logs (fault-facts) and assertions that print what they measured.
set -euo pipefail
BIN=$1 ROOT=$2
FAULTS=$ROOT/tests/faults
source "$ROOT/tests/integration/time_scale.sh"
if [ -z "${ADIT_IN_NETNS:-}" ]; then
  exec bash "$ROOT/tests/integration/netns.sh" ${NETNS_FLAGS:-} bash "$0" "$@"
fi
WORK=$(mktemp -d)
LAUNCH_PID=
cleanup() {
  if [ -n "$LAUNCH_PID" ] && kill -0 "$LAUNCH_PID" 2>/dev/null; then kill -INT "$LAUNCH_PID"; wait "$LAUNCH_PID" || true; fi
  if [ -n "${KEEP_WORK:-}" ]; then echo "work folder kept: $WORK"; else rm -rf "$WORK"; fi
}
trap cleanup EXIT
failed=0

# start_launch OUT LAUNCH_FILE [adit launch options...]: in the background; LAUNCH_PID, output in OUT.
start_launch() {
  local out=$1; shift
  "$BIN/adit" launch "$@" > "$out" 2>&1 &
  LAUNCH_PID=$!
}

# wait_launch: waits for the launcher to end; its exit code in LAUNCH_RC (not in a $(...): a subshell cannot
# wait for its parent's child).
wait_launch() {
  LAUNCH_RC=0
  wait "$LAUNCH_PID" || LAUNCH_RC=$?
  LAUNCH_PID=
}

# wait_line OUT REGEX SECONDS: prints the first launcher line matching REGEX; fails after SECONDS (scaled).
wait_line() {
  local deadline=$((SECONDS + $(scaled "$3"))) line
  while [ $SECONDS -lt $deadline ]; do
    if line=$(grep -E -m1 "$2" "$1"); then echo "$line"; return 0; fi
    sleep 0.2
  done
  echo "FAIL: no line matching '$2' within $3 s" >&2
  tail -20 "$1" >&2
  return 1
}

# fact FACTS KEY FIELDS...: the value of the line `KEY FIELDS... VALUE` of a fault-facts output (0 if absent).
fact() {
  local file=$1; shift
  awk -v key="$*" '{ v = $NF; $NF = ""; sub(/ +$/, ""); if ($0 == key) { found = v } } END { print (found == "" ? 0 : found) }' "$file"
}

# expect WHAT VALUE OP LIMIT (OP one of < <= > >= ==): prints ok/FAIL with the value.
expect() {
  if awk -v v="$2" -v l="$4" -v op="$3" 'BEGIN { exit !((op == "<" && v < l) || (op == "<=" && v <= l) || (op == ">" && v > l) || (op == ">=" && v >= l) || (op == "==" && v == l)) }'; then
    echo "ok: $1 = $2 ($3 $4)"
  else
    echo "FAIL: $1 = $2, expected $3 $4"
    failed=1
  fi
}

# expect_grep WHAT REGEX FILE
expect_grep() {
  if grep -qE "$2" "$3"; then echo "ok: $1"; else echo "FAIL: $1 (no line matching '$2' in $(basename "$3"))"; failed=1; fi
}

# start_reorder PERCENT IPTABLES_MATCH...: PERCENT % of the incoming datagrams that match are overtaken by 1-4
# later ones (reorder-queue behind an iptables NFQUEUE rule). REORDER_STATE is on, or none (and said so) where
# there is no reorder-queue, iptables or NFQUEUE target.
start_reorder() {
  local percent=$1; shift
  REORDER_STATE=none REORDER_MATCH=("$@")
  if [ "$percent" != 0 ] && [ -x "$BIN/reorder-queue" ] && command -v iptables > /dev/null &&
     iptables -A INPUT "$@" -j NFQUEUE --queue-num 7 --queue-bypass 2>/dev/null; then
    "$BIN/reorder-queue" --queue 7 --percent "$percent" --max-delay "${MAX_DELAY:-4}" > "$WORK/reorder.out" 2>&1 &
    REORDER_PID=$!
    trap 'kill -INT "$REORDER_PID" 2>/dev/null || true; cleanup' EXIT
    REORDER_STATE=on
  else
    echo "reordering left out (needs reorder-queue, iptables and the NFQUEUE target)"
  fi
}

# stop_reorder WHAT: removes the rule, ends reorder-queue, prints its report and checks that WHAT were overtaken.
stop_reorder() {
  [ "${REORDER_STATE:-none}" = on ] || return 0
  iptables -D INPUT "${REORDER_MATCH[@]}" -j NFQUEUE --queue-num 7 --queue-bypass
  kill -INT "$REORDER_PID"; wait "$REORDER_PID" || true
  cat "$WORK/reorder.out"
  expect "$1 held back and overtaken" "$(awk '/overtaken/ { print $4 }' "$WORK/reorder.out")" ">" 0
}

# The run folder a launch made under $WORK/logs (or $1).
run_dir() { ls -d "${1:-$WORK/logs}"/*-*/ | head -1; }

# The recorder's series of a run folder, in order (record.lcmlog, record.1.lcmlog, ...).
record_series() {
  local dir=$1 i=1
  echo "$dir/record.lcmlog"
  while [ -f "$dir/record.$i.lcmlog" ]; do echo "$dir/record.$i.lcmlog"; i=$((i + 1)); done
}

# run NAME: one simulated live run of ${LAUNCH_FILE:-launch/sim.launch.yaml} on $WORLD for $DURATION s (the packet
# loss and reordering tests); facts in $WORK/NAME.facts, APE rmse of ODOM_MAPPED in $WORK/NAME.ape ("none" without one)
run() {
  local name=$1 out=$WORK/$1.launch.out
  start_launch "$out" "${LAUNCH_FILE:-$ROOT/launch/sim.launch.yaml}" --set WORLD="$WORLD" --set DURATION="$DURATION" \
    --set 'RECORD=^(ODOM_MAPPED|GROUND_TRUTH|STATUS_.*)$' --log-dir "$WORK/$name" --quiet
  wait_launch
  echo "$name: adit launch exit code $LAUNCH_RC; $(tail -1 "$out")"
  mapfile -t series < <(record_series "$(run_dir "$WORK/$name")")
  mkdir -p "$WORK/$name.tum"
  "$BIN/fault-facts" --out "$WORK/$name.tum" "${series[@]}" > "$WORK/$name.facts"
  if "$BIN/adit" eval --gt "$WORK/$name.tum/truth.tum" --est "$WORK/$name.tum/mapped.tum" --align se3 > "$WORK/$name.eval" 2>&1; then
    awk '/all poses/ { for (i = 1; i <= NF; ++i) if ($i == "rmse") print $(i + 1) }' "$WORK/$name.eval" > "$WORK/$name.ape"
  else
    echo "no trajectory: $(tail -1 "$WORK/$name.eval")"
    echo none > "$WORK/$name.ape"  # fails an APE check
  fi
  grep -E '^(outputs|drops|restarted|status_gap_s) |lost_input|time_backwards|seq_reset' "$WORK/$name.facts" | tr '\n' ';'; echo
}

# expect_run_survived NAME BASELINE LABEL: the checks every network-fault run shares against its baseline run:
# no stage restarted or went silent for 5 s, sweeps still arrived, and the APE of NAME is within 20 % (or 2 cm,
# run-to-run noise at real time) of BASELINE's. Sets ARRIVED (sweeps at the feature stage) and the two APEs.
expect_run_survived() {
  local name=$1 baseline=$2 label=$3 p
  BASELINE_APE=$(cat "$WORK/$baseline.ape") RUN_APE=$(cat "$WORK/$name.ape")
  ARRIVED=$(fact "$WORK/$name.facts" outputs STATUS_FEATURE)
  for p in FEATURE ODOMETRY MAPPER LOOP_CLOSER; do
    expect "STATUS_$p restarts" "$(fact "$WORK/$name.facts" restarted STATUS_$p)" == 0
    expect "longest silence of STATUS_$p (s)" "$(fact "$WORK/$name.facts" status_gap_s STATUS_$p)" "<" 5
  done
  expect "sweeps that reached the feature stage (of $((DURATION * 10)))" "$ARRIVED" ">" 0
  expect "APE rmse with $label (m; $baseline $BASELINE_APE m)" "$RUN_APE" "<=" \
    "$(awk -v a="$BASELINE_APE" 'BEGIN { print (a * 1.2 > a + 0.02) ? a * 1.2 : a + 0.02 }')"
}
