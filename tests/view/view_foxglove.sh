#!/usr/bin/env bash
# adit view --foxglove read by Foxglove's own WebSocket protocol client (npm @foxglove/ws-protocol): a short
# simulated run played by `adit view --log ... --foxglove`; the client subscribes to every advertised channel
# and every message must be valid against Foxglove's published schemas; the sweeps, /tf, the trajectories and
# the map must arrive. The page's own stream is served beside it on the same port (checked by view_browser).
#   view_foxglove.sh BIN_DIR SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
source "$src"/tests/view/npm_tools.sh
npm_tools "$src" "$work"/../js
mkdir -p "$work" && cd "$work"
rm -rf out
"$bin"/adit sim --world roadway-loop --duration 12 --seed 7 -o run.lcmlog --gt gt.tum >/dev/null
"$bin"/adit replay run.lcmlog -o out --no-progress --record '^(LOOP_CLOSURE|POSE_GRAPH|GROUND_TRUTH|MAP_UPDATE)$' >/dev/null
"$bin"/adit view --log run.lcmlog --log out/output.lcmlog --foxglove --foxglove-sweep-every 2 --port 0 --speed 0.5 \
  --duration 60 > view.log 2>&1 &
view=$!
trap 'kill $view 2>/dev/null || true' EXIT
port=$(view_port view.log 50)
node ../js/foxglove_ws.js "ws://127.0.0.1:$port/ws" 22 > foxglove.json
node -e '
const s = require(process.argv[1]), t = s.topics;
const need = (c, m) => { if (!c) { console.error("FAIL: " + m + ": " + JSON.stringify(s)); process.exit(1); } };
need(t["/lidar/points"] && t["/lidar/points"].count >= 20, "sweeps (every 2nd of 120, from when the client joined)");
need(t["/tf"] && t["/tf"].count >= 60, "transforms");
for (const topic of ["/trajectory/odometry", "/trajectory/corrected", "/trajectory/ground_truth", "/map"])
  need(t[topic] && t[topic].count > 0, topic);
console.log("view_foxglove: " + Object.entries(t).map(([k, v]) => `${k} ${v.count}`).join(", "));
' "$work"/foxglove.json
