#!/usr/bin/env bash
# adit view on a live run: the simulator and the four stage processes over UDP multicast (launch/sim.launch.yaml,
# 30 s) in a private network namespace, adit view --allow-commands listening; Debian's chromium opens the page,
# which must fill from the live bus (map, trajectory, one STATUS row per process), then asks for save_map twice:
# "live_test" (published: the loop closer writes live_test.pcd into its run folder) and "../escape" (refused by
# adit view itself: never published). The npm packages are installed first, then the script runs itself again
# inside a private network namespace (tests/integration/netns.sh); skipped without chromium or npm.
#   view_live.sh BIN_DIR SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
chromium=${CHROMIUM:-/usr/bin/chromium}
[ -x "$chromium" ] || { echo "SKIP: no chromium ($chromium; scripts/setup.sh installs Debian's)"; exit 77; }
[ -f "$bin"/../share/adit/view/three.module.js ] || { echo "SKIP: three.js was not installed into the build"; exit 77; }
source "$src"/tests/view/npm_tools.sh
if [ -z "${ADIT_IN_NETNS:-}" ]; then
  npm_tools "$src" "$work"/../js  # with the network; the namespace has none
  exec "$src"/tests/integration/netns.sh "$0" "$@"
fi
mkdir -p "$work" && cd "$work"
rm -rf runs view.png
url='udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608'
"$bin"/adit view --lcm-url "$url" --port 0 --allow-commands --duration 120 > view.log 2>&1 &
view=$!
ADIT_LCM_URL="$url" "$bin"/adit launch "$src"/launch/sim.launch.yaml --set DURATION=30 --set RECORD=MAPPER_COMMAND \
  --log-dir "$work"/runs > launch.log 2>&1 &
launch=$!
trap 'kill $view $launch 2>/dev/null || true' EXIT
port=$(view_port view.log 50)
ADIT_SAVE_MAP=live_test,../escape node ../js/view_page.js "http://127.0.0.1:$port/" view.png 90 > state.json
wait $launch || true
node -e '
const s = require(process.argv[1]);
const need = (c, m) => { if (!c) { console.error("FAIL: " + m + ": " + JSON.stringify(s)); process.exit(1); } };
need(s.map_points > 0 && s.trajectory.odometry > 10 && s.sweep_points > 0, "the live run did not reach the page");
const names = s.status.map((r) => r.process);
for (const p of ["feature", "odometry", "mapper", "loop_closer"]) need(names.some((n) => n.replace("-", "_") === p), "no STATUS row for " + p);
console.log(`view_live: ${s.map_points} map points, ${s.trajectory.odometry} poses, STATUS of ${names.join(" ")}`);
' "$work"/state.json
run=$(ls -d "$work"/runs/*/ | head -1)
[ -f "$run"/live_test.pcd ] || { echo "FAIL: save_map live_test from the page did not reach the loop closer ($run)"; ls "$run"; exit 1; }
commands=$("$bin"/adit info "$run"/record.lcmlog | awk '$1 == "MAPPER_COMMAND" { print $2 }')
[ "$commands" = 1 ] || { echo "FAIL: $commands MAPPER_COMMAND message(s) on the bus, expected 1 (../escape must be refused)"; exit 1; }
grep -q "save_map '../escape'" view.log || { echo "FAIL: adit view did not report refusing ../escape"; exit 1; }
echo "view_live: save_map from the page wrote live_test.pcd; ../escape refused"
