#!/usr/bin/env bash
# adit view's stream to one browser on a VLP-16 run at 1 m/s, against issue 19's budget of 1 MB/s: simulates
# DURATION s (default 20) of roadway-loop at a cruise speed of 1 m/s, replays it (MAP_UPDATE recorded), serves
# the logs with `adit view --log ... --paused` at real-time speed, and lets Debian's chromium play it through
# while measuring the bytes the page received per second. Fails above 1 MB/s, or when the page got no map.
# Prints the figure and the page's state; screenshot in WORK_DIR. Skipped (77) without chromium, node/npm, or
# the npm packages.
#   tests/view/view_bandwidth.sh BIN_DIR SOURCE_DIR WORK_DIR [DURATION_S]
set -euo pipefail
bin=$1 src=$2 work=$3 duration=${4:-20}
chromium=${CHROMIUM:-/usr/bin/chromium}
[ -x "$chromium" ] || { echo "SKIP: no chromium ($chromium; scripts/setup.sh installs Debian's)"; exit 77; }
[ -f "$bin"/../share/adit/view/three.module.js ] || { echo "SKIP: three.js was not installed into the build (npm unavailable at build time)"; exit 77; }
source "$src"/tests/view/npm_tools.sh
npm_tools "$src" "$work"/../js
mkdir -p "$work" && cd "$work"
rm -rf out ./*.lcmlog bandwidth.json bandwidth.png
cat > speed.yaml <<'YAML'
sim:
  motion:
    cruise_speed: 1.0
    max_speed: 1.2
YAML
"$bin"/adit sim --config speed.yaml --world roadway-loop --duration "$duration" -o run.lcmlog --gt gt.tum >/dev/null
"$bin"/adit replay run.lcmlog -o out --no-progress --record '^(LOOP_CLOSURE|POSE_GRAPH|GROUND_TRUTH|MAP_UPDATE)$' >/dev/null
"$bin"/adit view --log run.lcmlog --log out/output.lcmlog --port 0 --bind 127.0.0.1 --paused --duration $((duration + 60)) \
  > view.log 2>&1 &
view=$!
trap 'kill $view 2>/dev/null || true' EXIT
port=$(view_port view.log 100)
node ../js/view_page.js "http://127.0.0.1:$port/" bandwidth.png 60 "$((duration - 2))" > bandwidth.json
node -e '
const s = require(process.argv[1]), budget = 1e6;
const need = (c, m) => { if (!c) { console.error("FAIL: " + m + ": " + JSON.stringify(s.measured)); process.exit(1); } };
need(s.measured && s.measured.bytes > 0, "no measurement");
need(s.map_points > 1000 && s.trajectory.odometry > 10, "the page got no map or trajectory");
console.log(`stream to one browser: ${(s.measured.bytes_per_s / 1e3).toFixed(1)} kB/s over ${s.measured.seconds.toFixed(1)} s ` +
  `(${(s.measured.bytes / 1e6).toFixed(2)} MB); map ${s.map_points} points in ${s.submaps} submaps, ${s.trajectory.odometry} poses, ` +
  `sweep ${s.sweep_points} points; frame time ${s.measured.frame_ms.toFixed(1)} ms (headless chromium, SwiftShader)`);
need(s.measured.bytes_per_s <= budget, `${(s.measured.bytes_per_s / 1e3).toFixed(1)} kB/s is over the budget of 1 MB/s`);
' "$work"/bandwidth.json
