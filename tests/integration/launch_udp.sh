#!/usr/bin/env bash
# `adit launch` of the lidar bridge + adit-feature + lcm-logger over real UDP multicast, inside a private
# network namespace: the recorded log must hold every sweep the bridge sent, every FEATURES the feature
# process made from them, and the STATUS messages of both.
#   launch_udp.sh <bin_dir> <shared_data_dir>
set -euo pipefail
BIN=$1 DATA=$2
# Inside a private network namespace (netns.sh: exit 77 = skipped, with the reason, where none can be made).
[ -n "${ADIT_IN_NETNS:-}" ] || exec bash "$(dirname "$0")/netns.sh" bash "$0" "$@"

WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
"$BIN/adit" launch "$(dirname "$0")/udp.launch.yaml" --set DATA="$DATA" --log-dir "$WORK" --quiet
RUN=$(ls -d "$WORK"/udp-*)
"$BIN/adit" info "$RUN/record.lcmlog" | tee "$WORK/info.txt"

failed=0
expect() {  # channel op number
  local n
  n=$(awk -v c="$1" '$1 == c { print $2 }' "$WORK/info.txt")
  n=${n:-0}
  if [ "$n" "$2" "$3" ]; then echo "ok: $1 has $n messages ($2 $3)"; else echo "FAIL: $1 has $n messages, expected $2 $3"; failed=1; fi
}
expect LIDAR_POINTS -eq 10
expect FEATURES -eq 10
expect STATUS_LIDAR_BRIDGE -ge 1
expect STATUS_FEATURE -ge 2
grep -q "published 10 messages" "$RUN/bridge.log" || { echo "FAIL: bridge did not report 10 sweeps"; cat "$RUN/bridge.log"; failed=1; }
exit $failed
