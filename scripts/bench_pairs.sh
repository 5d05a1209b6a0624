#!/usr/bin/env bash
# Two builds' speed side by side on a machine whose speed drifts (a shared VM: a third from day to day, ~10 %
# within an hour): `adit bench pipeline` runs of the two builds taken in turn, before, after, before, after ...,
# then `adit bench compare --pairs`, which judges each figure by the median of the pairs' changes.
#   scripts/bench_pairs.sh BEFORE_ADIT AFTER_ADIT [PAIRS=5] [-- bench pipeline arguments]
# e.g. scripts/bench_pairs.sh ../adit-old/build/bin/adit build/bin/adit 6 -- --log run.lcmlog
# Without arguments after --, each run is 20 s of simulated roadway-loop. Both builds read this checkout's
# launch/config/pipeline.yaml unless the arguments give a --config. The JSON files stay in a temporary
# folder whose name is printed; they are compared by this checkout's build/bin/adit (either build may be older
# than --pairs); the exit status is adit bench compare's (1: a regression beyond 10 %).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
if [ $# -lt 2 ]; then
  sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'
  exit 2
fi
BEFORE=$1 AFTER=$2
shift 2
PAIRS=5
if [ $# -gt 0 ] && [ "$1" != "--" ]; then PAIRS=$1; shift; fi
[ $# -gt 0 ] && [ "$1" = "--" ] && shift
ARGS=("$@")
[ ${#ARGS[@]} -eq 0 ] && ARGS=(--sensor vlp16 --world roadway-loop --duration 20)
HAS_CONFIG=0
for arg in "${ARGS[@]}"; do [ "$arg" = --config ] && HAS_CONFIG=1; done
[ $HAS_CONFIG = 1 ] || ARGS+=(--config "$ROOT/launch/config/pipeline.yaml")
OUT=$(mktemp -d)
echo "runs in $OUT"
FILES=()
for ((i = 1; i <= PAIRS; ++i)); do
  for side in before after; do
    bin=$BEFORE
    [ "$side" = after ] && bin=$AFTER
    "$bin" bench pipeline "${ARGS[@]}" --json "$OUT/$side-$i.json" >"$OUT/$side-$i.txt" 2>&1 ||
      { echo "$side run $i failed: see $OUT/$side-$i.txt" >&2; exit 3; }
    FILES+=("$OUT/$side-$i.json")
  done
  echo "pair $i of $PAIRS done"
done
"$ROOT/build/bin/adit" bench compare --pairs "${FILES[@]}"
