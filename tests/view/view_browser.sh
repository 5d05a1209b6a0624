#!/usr/bin/env bash
# adit view end to end in a real browser: a short simulated run (sensor log, replay products with MAP_UPDATE,
# STATUS from the feature process run on the log) served by `adit view --log`; Debian's chromium (headless)
# opens the page and the page's own state (window.aditState) must show the map, the trajectory and the STATUS
# rows that the logs hold, and the speed menu the server's --speed; a screenshot goes to WORK_DIR/view.png.
# Also: an unknown path is a 404.
# Skipped (77) without chromium, node/npm, or the npm packages.
#   view_browser.sh BIN_DIR SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
chromium=${CHROMIUM:-/usr/bin/chromium}
[ -x "$chromium" ] || { echo "SKIP: no chromium ($chromium; scripts/setup.sh installs Debian's)"; exit 77; }
[ -f "$bin"/../share/adit/view/three.module.js ] || { echo "SKIP: three.js was not installed into the build (npm unavailable at build time)"; exit 77; }
source "$src"/tests/view/npm_tools.sh
npm_tools "$src" "$work"/../js
mkdir -p "$work" && cd "$work"
rm -rf out view.png
"$bin"/adit sim --world roadway-loop --duration 12 --seed 5 -o run.lcmlog --gt gt.tum >/dev/null
"$bin"/adit replay run.lcmlog -o out --no-progress --record '^(LOOP_CLOSURE|POSE_GRAPH|GROUND_TRUTH|MAP_UPDATE)$' >/dev/null
"$bin"/adit-feature --lcm-url "file://$work/run.lcmlog?speed=0" --out-url "file://$work/feature.lcmlog?mode=w" >/dev/null 2>&1
/usr/bin/python3 "$src"/tests/view/restamp_status.py feature.lcmlog status.lcmlog run.lcmlog
poses=$("$bin"/adit info out/output.lcmlog | awk '$1 == "ODOM_MAPPED" { print $2 }')

"$bin"/adit view --log run.lcmlog --log out/output.lcmlog --log status.lcmlog --port 0 --bind 127.0.0.1 --speed 4 \
  --duration 120 > view.log 2>&1 &
view=$!
trap 'kill $view 2>/dev/null || true' EXIT
port=$(view_port view.log 50)
code=$(curl -s -o /dev/null -w '%{http_code}' "http://127.0.0.1:$port/no-such-file.js")
[ "$code" = 404 ] || { echo "FAIL: unknown path gave HTTP $code"; exit 1; }

node ../js/view_page.js "http://127.0.0.1:$port/" view.png 90 > state.json
node -e '
const s = require(process.argv[1]), poses = Number(process.argv[2]);
const need = (c, m) => { if (!c) { console.error("FAIL: " + m + ": " + JSON.stringify(s)); process.exit(1); } };
need(s.connected, "not connected");
need(s.map_points > 1000 && s.submaps > 1, "map too small");
need(s.sweep_points > 1000 && s.sweep_points <= 6000, "sweep not shown or not decimated");
need(s.trajectory.odometry > 10 && s.trajectory.odometry <= poses, "odometry trajectory");
need(s.trajectory.corrected === s.trajectory.odometry, "corrected trajectory length differs");
need(s.trajectory.ground_truth > 10, "ground truth trajectory");
const feature = s.status.find((r) => r.process === "feature");
need(feature && feature.inputs > 0, "no STATUS row for the feature process");
need(s.page_errors.length === 0, "page errors");
need(s.speed_menu === "4", `the speed menu shows ${s.speed_menu}, not the --speed 4 of the server`);
console.log(`view_browser: ${s.map_points} map points in ${s.submaps} submaps, ${s.trajectory.odometry} of ${poses} poses, ` +
  `${s.status.length} STATUS row(s), ${s.frames} frames, ${(s.bytes / 1e6).toFixed(2)} MB, frame time ${s.frame_ms.toFixed(1)} ms`);
' "$work"/state.json "$poses"
[ -s view.png ] || { echo "FAIL: no screenshot"; exit 1; }
