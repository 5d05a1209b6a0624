#!/usr/bin/env bash
# Runs the DiskFull.* tests of test_live on a 16 MB tmpfs of their own (a private mount namespace: root
# `unshare -m`, else `unshare -rm`); skipped (77) where neither is allowed.
set -u
BIN=$1
if [[ $(id -u) -eq 0 ]]; then NS=(unshare -m); else NS=(unshare -rm); fi
DIR=$(mktemp -d)
trap 'rm -rf "$DIR"' EXIT
if ! "${NS[@]}" sh -c "mount -t tmpfs -o size=16m tmpfs '$DIR'" 2>/dev/null; then
  echo "SKIP: cannot mount a tmpfs in a private mount namespace here"
  exit 77
fi
exec "${NS[@]}" sh -c 'mount -t tmpfs -o size=16m tmpfs "$1" && ADIT_FULL_DISK_DIR="$1" exec "$2/test_live" --gtest_filter="DiskFull.*"' \
  _ "$DIR" "$BIN"
