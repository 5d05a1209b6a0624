#!/usr/bin/env bash
# adit export mcap read back by an independent reader: a short simulated run, replayed (MAP_UPDATE recorded),
# exported with zstd and uncompressed chunks, and each file read by Foxglove's @mcap/core (tests/view/js/
# read_mcap.js: both of its readers, every CRC, every message against Foxglove's published JSON Schemas).
# The message counts must be the input logs' counts as `adit info` gives them; two exports are byte-identical.
#   mcap_reader.sh BIN_DIR SOURCE_DIR WORK_DIR
set -euo pipefail
bin=$1 src=$2 work=$3
source "$src"/tests/view/npm_tools.sh
npm_tools "$src" "$work"/../js
mkdir -p "$work" && cd "$work"
rm -rf run out ./*.mcap
"$bin"/adit sim --world roadway-loop --duration 12 --seed 3 -o run.lcmlog --gt gt.tum >/dev/null
"$bin"/adit replay run.lcmlog -o out --no-progress --record '^(LOOP_CLOSURE|POSE_GRAPH|STATUS_.*|GROUND_TRUTH|MAP_UPDATE)$' >/dev/null
count() {  # count LOG CHANNEL: messages of CHANNEL in LOG per adit info
  "$bin"/adit info "$1" | awk -v c="$2" '$1 == c { print $2; found = 1 } END { if (!found) print 0 }'
}
sweeps=$(count run.lcmlog LIDAR_POINTS)
truth=$(count run.lcmlog GROUND_TRUTH)
mapped=$(count out/output.lcmlog ODOM_MAPPED)
[ "$sweeps" -gt 100 ] && [ "$mapped" -gt 100 ] || { echo "FAIL: the run is too short ($sweeps sweeps, $mapped poses)"; exit 1; }
for compression in zstd none; do
  "$bin"/adit export mcap run.lcmlog out/output.lcmlog -o run-$compression.mcap --compression $compression --chunk-mb 1
  node ../js/read_mcap.js run-$compression.mcap "/lidar/points=$sweeps" "/tf=$((mapped + truth))" > summary-$compression.json
done
# Deterministic: the same logs give the same bytes.
"$bin"/adit export mcap run.lcmlog out/output.lcmlog -o again.mcap --compression zstd --chunk-mb 1 >/dev/null
cmp -s run-zstd.mcap again.mcap || { echo "FAIL: two exports of the same logs differ"; exit 1; }
node -e '
const s = require(process.argv[1]), plain = require(process.argv[2]);
const need = (c, m) => { if (!c) { console.error("FAIL: " + m); process.exit(1); } };
need(s.compression.join() === "zstd" && plain.compression.join() === "", "chunk compression not as asked");
need(JSON.stringify(s.topics) === JSON.stringify(plain.topics), "the two encodings read back differently");
need(s.chunks > 1, "one chunk only");
need(s.topics["/map"] && s.topics["/map"].last_points > 1000, "no corrected map");
for (const t of ["/trajectory/odometry", "/trajectory/corrected", "/trajectory/ground_truth"])
  need(s.topics[t] && s.topics[t].last_poses > 20, t + " missing or short");
const a = s.topics["/trajectory/ground_truth"].last_position, b = s.topics["/trajectory/odometry"].last_position;
const d = Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
need(d < 0.5, "ground truth and odometry end " + d.toFixed(3) + " m apart");
console.log("mcap_reader: " + s.messages + " messages in " + s.chunks + " chunks read back; ends " + d.toFixed(3) + " m apart");
' "$work"/summary-zstd.json "$work"/summary-none.json
