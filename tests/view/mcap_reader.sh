#!/usr/bin/env bash
# adit export mcap read back by an independent reader: a short simulated run round a small loop (loops close),
# replayed (MAP_UPDATE recorded), STATUS from the feature process run on the log, exported with zstd and
# uncompressed chunks, and each file read by Foxglove's @mcap/core (tests/view/js/read_mcap.js: both of its
# readers, every CRC, every message against Foxglove's published JSON Schemas). The channels and their schemas
# must be the ones README documents (Watching a run: Foxglove), every one present; the message counts must be
# the input logs' counts as `adit info` gives them; two exports are byte-identical.
#   mcap_reader.sh BIN_DIR SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
source "$src"/tests/view/npm_tools.sh
npm_tools "$src" "$work"/../js
mkdir -p "$work" && cd "$work"
rm -rf run out ./*.mcap ./*.lcmlog
"$bin"/adit sim --config "$src"/tests/view/short_loop.yaml --duration 80 --seed 3 -o run.lcmlog --gt gt.tum >/dev/null
"$bin"/adit replay run.lcmlog -o out --no-progress --record '^(LOOP_CLOSURE|POSE_GRAPH|STATUS_.*|GROUND_TRUTH|MAP_UPDATE)$' >/dev/null
"$bin"/adit-feature --lcm-url "file://$work/run.lcmlog?speed=0" --out-url "file://$work/feature.lcmlog?mode=w" >/dev/null 2>&1
/usr/bin/python3 "$src"/tests/view/restamp_status.py feature.lcmlog status.lcmlog run.lcmlog
rm feature.lcmlog  # ~110 MB of features
count() {  # count LOG CHANNEL: messages of CHANNEL in LOG per adit info
  "$bin"/adit info "$1" | awk -v c="$2" '$1 == c { print $2; found = 1 } END { if (!found) print 0 }'
}
sweeps=$(count run.lcmlog LIDAR_POINTS)
truth=$(count run.lcmlog GROUND_TRUTH)
mapped=$(count out/output.lcmlog ODOM_MAPPED)
loops=$(count out/output.lcmlog LOOP_CLOSURE)
status=$(count status.lcmlog STATUS_FEATURE)
[ "$sweeps" -gt 700 ] && [ "$mapped" -gt 700 ] || { echo "FAIL: the run is too short ($sweeps sweeps, $mapped poses)"; exit 1; }
[ "$loops" -gt 0 ] && [ "$status" -gt 0 ] || { echo "FAIL: no loop closed ($loops) or no STATUS ($status)"; exit 1; }
every=8  # --sweep-every: the first sweep and every 8th after it (keeps the files near 100 MB)
logs=(run.lcmlog out/output.lcmlog status.lcmlog)
for compression in zstd none; do
  "$bin"/adit export mcap "${logs[@]}" -o run-$compression.mcap --compression $compression --chunk-mb 1 --sweep-every $every
  node ../js/read_mcap.js run-$compression.mcap "/lidar/points=$(( (sweeps - 1) / every + 1 ))" "/tf=$((mapped + truth))" \
    "/status/feature=$status" > summary-$compression.json
done
# Deterministic: the same logs give the same bytes.
"$bin"/adit export mcap "${logs[@]}" -o again.mcap --compression zstd --chunk-mb 1 --sweep-every $every >/dev/null
cmp -s run-zstd.mcap again.mcap || { echo "FAIL: two exports of the same logs differ"; exit 1; }
node -e '
const s = require(process.argv[1]), plain = require(process.argv[2]), loops = Number(process.argv[3]);
const need = (c, m) => { if (!c) { console.error("FAIL: " + m); process.exit(1); } };
need(s.compression.join() === "zstd" && plain.compression.join() === "", "chunk compression not as asked");
need(JSON.stringify(s.topics) === JSON.stringify(plain.topics), "the two encodings read back differently");
need(s.chunks > 1, "one chunk only");
// The channels README documents for adit export mcap, each with its schema (JSON messages, JSON Schemas).
const documented = {
  "/lidar/points": "foxglove.PointCloud", "/map": "foxglove.PointCloud", "/tf": "foxglove.FrameTransform",
  "/trajectory/odometry": "foxglove.PosesInFrame", "/trajectory/corrected": "foxglove.PosesInFrame",
  "/trajectory/ground_truth": "foxglove.PosesInFrame", "/loops": "foxglove.SceneUpdate", "/status/feature": "adit.Status",
};
const channels = Object.keys(s.topics).sort(), expected = Object.keys(documented).sort();
need(JSON.stringify(channels) === JSON.stringify(expected), "channels " + channels.join(" ") + ", expected " + expected.join(" "));
for (const [topic, schema] of Object.entries(documented)) {
  const t = s.topics[topic];
  need(t.schema === schema, topic + ": schema " + t.schema + ", expected " + schema);
  need(t.encoding === "json" && t.schema_encoding === "jsonschema", topic + ": encodings " + t.encoding + " / " + t.schema_encoding);
  need(t.count > 0, topic + ": no message");
}
need(s.topics["/map"].last_points > 1000, "no corrected map");
need(s.topics["/loops"].last_lines === loops, "the last /loops draws " + s.topics["/loops"].last_lines + " lines, the run closed " + loops + " loops");
for (const t of ["/trajectory/odometry", "/trajectory/corrected", "/trajectory/ground_truth"])
  need(s.topics[t].last_poses > 20, t + " short");
const a = s.topics["/trajectory/ground_truth"].last_position, b = s.topics["/trajectory/odometry"].last_position;
const d = Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
need(d < 0.5, "ground truth and odometry end " + d.toFixed(3) + " m apart");
console.log("mcap_reader: " + s.messages + " messages on " + channels.length + " channels in " + s.chunks + " chunks read back; " +
  loops + " loops drawn; ends " + d.toFixed(3) + " m apart");
' "$work"/summary-zstd.json "$work"/summary-none.json "$loops"
rm -f run-none.mcap again.mcap  # ~170 MB; run-zstd.mcap stays for a look in Foxglove
