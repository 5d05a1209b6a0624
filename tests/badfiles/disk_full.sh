#!/usr/bin/env bash
# Disk full while writing a log: `adit import` and `adit replay` on a 64 kB tmpfs must exit non-zero with a
# one-line error naming the log, and leave neither the log under its final name nor a temp file.
# Needs a private mount namespace (root: unshare -m; otherwise unshare -rm); skipped (77) where neither works.
set -u
BIN=$1 DATA=$2
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
if [[ $(id -u) -eq 0 ]]; then NS=(unshare -m); else NS=(unshare -rm); fi
if ! "${NS[@]}" sh -c "mount -t tmpfs -o size=64k tmpfs '$WORK'" 2>/dev/null; then
  echo "SKIP: cannot mount a tmpfs in a private mount namespace here"
  exit 77
fi
mkdir -p "$WORK/seq/velodyne" "$WORK/full"
printf '0.0\n0.103\n' > "$WORK/seq/times.txt"
cp "$DATA/kitti_mini/sequences/00/velodyne/00000"[01].bin "$WORK/seq/velodyne/"
"$BIN/adit" import kitti "$WORK/seq" -o "$WORK/input.lcmlog" >/dev/null 2>&1 || { echo "FAIL: cannot make the input log"; exit 1; }

fail=0
check() {  # name status output log_name
  local name=$1 status=$2 output=$3 log=$4
  local errors=$(grep -c 'error' <<<"$output")
  if [[ $status -eq 0 || $status -ge 128 ]]; then echo "FAIL $name: exit status $status"; fail=1; fi
  if ! grep 'error' <<<"$output" | grep -q "$log"; then echo "FAIL $name: no error line names $log"; fail=1; fi
  if grep -q 'No space left on device' <<<"$output"; then :; else echo "FAIL $name: the error does not say the disk is full"; fail=1; fi
  if [[ $errors -gt 1 ]]; then echo "FAIL $name: $errors error lines"; fail=1; fi
  if grep -q '^left: ' <<<"$output"; then echo "FAIL $name: files left: $(grep '^left: ' <<<"$output" | tr '\n' ' ')"; fail=1; fi
  echo "$name: exit $status: $(grep 'error' <<<"$output" | head -1)"
}
out=$("${NS[@]}" sh -c 'mount -t tmpfs -o size=64k tmpfs "$1/full" || exit 99
  "$2/adit" import kitti "$1/seq" -o "$1/full/out.lcmlog"; s=$?; ls -A "$1/full" | sed "s/^/left: /"; exit $s' _ "$WORK" "$BIN" 2>&1)
check "import" $? "$out" "out.lcmlog"
out=$("${NS[@]}" sh -c 'mount -t tmpfs -o size=64k tmpfs "$1/full" || exit 99
  "$2/adit" replay "$1/input.lcmlog" -o "$1/full/run" --stages feature --record-all --no-progress; s=$?
  ls -A "$1/full/run" 2>/dev/null | grep -i lcmlog | sed "s/^/left: /"; exit $s' _ "$WORK" "$BIN" 2>&1)
check "replay" $? "$out" "output.lcmlog"
exit $fail
