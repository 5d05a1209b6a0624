#!/usr/bin/env bash
# Measures adit view's stream to one browser on a VLP-16 run at 1 m/s: simulates DURATION s (default 60) of
# roadway-loop at a cruise speed of 1 m/s, replays it (MAP_UPDATE recorded), serves the logs with
# `adit view --log ... --paused` at real-time speed, and lets Debian's chromium play it through while measuring
# the bytes the page received per second. Prints the figure and the page's state; screenshot in WORK_DIR.
#   tests/view/view_bandwidth.sh BUILD_BIN_DIR WORK_DIR [DURATION_S]
set -euo pipefail
bin=$(cd "$1" && pwd) work=$2 duration=${3:-60}
src=$(cd "$(dirname "$0")/../.." && pwd)
source "$src"/tests/view/npm_tools.sh
npm_tools "$src" "$work"/js
cd "$work"
cat > speed.yaml <<'YAML'
sim:
  motion:
    cruise_speed: 1.0
    max_speed: 1.2
YAML
"$bin"/adit sim --config speed.yaml --world roadway-loop --duration "$duration" -o run.lcmlog --gt gt.tum >/dev/null
"$bin"/adit replay run.lcmlog -o out --no-progress --record '^(LOOP_CLOSURE|POSE_GRAPH|GROUND_TRUTH|MAP_UPDATE)$' >/dev/null
"$bin"/adit view --log run.lcmlog --log out/output.lcmlog --port 0 --paused --duration $((duration + 60)) > view.log 2>&1 &
view=$!
trap 'kill $view 2>/dev/null || true' EXIT
port=$(view_port view.log 100)
node js/view_page.js "http://127.0.0.1:$port/" bandwidth.png 60 "$((duration - 2))" > bandwidth.json || true
node -e '
const s = require(process.argv[1]);
if (!s.measured) { console.error("no measurement"); process.exit(1); }
console.log(`stream to one browser: ${(s.measured.bytes_per_s / 1e3).toFixed(1)} kB/s over ${s.measured.seconds.toFixed(1)} s ` +
  `(${(s.measured.bytes / 1e6).toFixed(2)} MB); map ${s.map_points} points in ${s.submaps} submaps, ${s.trajectory.odometry} poses, ` +
  `sweep ${s.sweep_points} points; frame time ${s.measured.frame_ms.toFixed(1)} ms (headless chromium, SwiftShader)`);
' "$work"/bandwidth.json
