#!/usr/bin/env bash
# The two scopes of a live run over real UDP multicast, inside a private network namespace (the host's routes
# are neither needed nor touched). launch/live.launch.yaml runs the four stages and adit-lan-relay on the
# robot's bus (ttl=0); the simulator feeds it VLP-16 sweeps in real time; the launch records every channel of
# the robot's bus and a second lcm-logger records the LAN group. Checks:
#  - the LAN carries exactly the documented monitoring set (README "Deployment"), ODOM_MAPPED as the pose
#    alone, under 1 MB/s;
#  - the robot's bus keeps the heavy channels, each within its per-sweep byte budget, all of them <= 0.4 MB.
#   lan_scope.sh <bin_dir> <source_dir>
set -euo pipefail
BIN=$1 ROOT=$2
if [ -z "${ADIT_IN_NETNS:-}" ]; then
  exec unshare -rn env ADIT_IN_NETNS=1 bash "$0" "$@"
fi
ip link set lo up multicast on
ip route add 224.0.0.0/4 dev lo

WORK=$(mktemp -d)
LAN_LOGGER=
trap '[ -n "$LAN_LOGGER" ] && kill "$LAN_LOGGER" 2>/dev/null; rm -rf "$WORK"' EXIT
LOCAL='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608'
LAN='udpm://239.255.76.68:7668?ttl=1'
SIM_S=8
source "$ROOT/tests/integration/time_scale.sh"

lcm-logger -q -f --lcm-url="$LAN&recv_buf_size=8388608" "$WORK/lan.lcmlog" &
LAN_LOGGER=$!
ADIT_LCM_URL="$LOCAL" "$BIN/adit" launch "$ROOT/launch/live.launch.yaml" --set RECORD='.*' --set LAN_URL="$LAN" \
  --log-dir "$WORK" --quiet --duration "$(scaled $((SIM_S + 8)))" &
LAUNCH=$!
sleep "$(scaled 3)"
"$BIN/adit" sim --live --lcm-url "$LOCAL" --world roadway-loop --sensor vlp16 --duration $SIM_S --seed 4 --rate "$RATE"
wait $LAUNCH
kill -INT "$LAN_LOGGER"; wait "$LAN_LOGGER" || true; LAN_LOGGER=
RUN=$(ls -d "$WORK"/live-*)
echo "== robot's bus"; "$BIN/adit" info "$RUN/record.lcmlog" | tee "$WORK/local.txt"
echo "== LAN";         "$BIN/adit" info "$WORK/lan.lcmlog" | tee "$WORK/lan.txt"

failed=0
fail() { echo "FAIL: $*"; failed=1; }
field() { awk -v c="$2" -v k="$3" '$1 == c { print $k }' "$1"; }  # file channel column
SWEEPS=$(field "$WORK/local.txt" LIDAR_POINTS 2); SWEEPS=${SWEEPS:-0}
[ "$SWEEPS" -ge $((SIM_S * 10 - 2)) ] || fail "the robot's bus recorded $SWEEPS sweeps of $((SIM_S * 10))"

# The LAN: the documented set, nothing else.
DOCUMENTED='^(ODOM_MAPPED|POSE_GRAPH|LOOP_CLOSURE|MAP_UPDATE|LIDAR_POINTS|STATUS_.*)$'
for c in $(awk 'NR > 1 && $1 != "total" { print $1 }' "$WORK/lan.txt"); do
  [[ "$c" =~ $DOCUMENTED ]] || fail "$c crossed to the LAN"
done
for c in ODOM_MAPPED LIDAR_POINTS STATUS_FEATURE STATUS_ODOMETRY STATUS_MAPPER STATUS_LOOP_CLOSER STATUS_LAN_RELAY \
         STATUS_LIDAR_BRIDGE; do
  [ -n "$(field "$WORK/lan.txt" "$c" 2)" ] || fail "$c did not reach the LAN"
done
awk -v s="$SWEEPS" '$1 == "LIDAR_POINTS" { exit !($2 <= s / 10 + 1) }' "$WORK/lan.txt" || fail "LIDAR_POINTS not decimated on the LAN"
awk '$1 == "ODOM_MAPPED" { exit !($7 < 1.0) }' "$WORK/lan.txt" || fail "ODOM_MAPPED on the LAN is not the pose alone"
# LAN rate over the simulated time: bytes / (sweeps / 10 Hz).
awk -v s="$SWEEPS" '$1 == "total" { r = $3 / (s / 10); printf "LAN: %.3f MB/s\n", r; exit !(r < 1.0) }' "$WORK/lan.txt" \
  || fail "the LAN carries 1 MB/s or more"

# The robot's bus: per-sweep budget of each channel (kB) and of all of them.
budget() {  # channel max_kB_per_message
  local kb; kb=$(field "$WORK/local.txt" "$1" 7)
  if [ -z "$kb" ]; then fail "$1 missing on the robot's bus"; return; fi
  awk -v k="$kb" -v m="$2" -v c="$1" 'BEGIN { printf "%s: %.1f kB per message (budget %d)\n", c, k, m; exit !(k <= m) }' \
    || fail "$1 over budget"
}
budget LIDAR_POINTS 110
budget FEATURES 120
budget ODOM_SCAN 100
budget ODOM_MAPPED 40
awk -v s="$SWEEPS" '$1 == "total" { kb = $3 * 1000 / s; printf "all channels: %.1f kB per sweep\n", kb; exit !(kb <= 400) }' \
  "$WORK/local.txt" || fail "the bus carries more than 0.4 MB per sweep"
exit $failed
