#!/usr/bin/env bash
# Installs adit view's page into the build: the page's own files, and three.js from npm (pinned by
# package-lock.json) so that the robot serves everything without internet. Without node/npm or network the
# page's files are still installed and adit view warns that three.js is missing (the build does not fail).
#   install_web.sh SOURCE_DIR DEST_DIR
set -uo pipefail
src=$1 dest=$2
mkdir -p "$dest"
cp "$src"/index.html "$src"/app.js "$src"/stream.js "$dest"/
npm_dir="$dest"/npm
if cmp -s "$src"/package-lock.json "$npm_dir"/package-lock.json && [ -f "$dest"/three.module.js ]; then exit 0; fi
if ! command -v npm >/dev/null; then
  echo "install_web.sh: npm not found: adit view's page will lack three.js (scripts/setup.sh installs nodejs npm)" >&2
  exit 0
fi
mkdir -p "$npm_dir"
cp "$src"/package.json "$src"/package-lock.json "$npm_dir"/
if ! (cd "$npm_dir" && timeout 300 npm ci --no-audit --no-fund --silent); then
  echo "install_web.sh: npm ci failed (no network?): adit view's page will lack three.js" >&2
  rm -f "$npm_dir"/package-lock.json
  exit 0
fi
three="$npm_dir"/node_modules/three
cp "$three"/build/three.module.js "$three"/build/three.core.js "$three"/examples/jsm/controls/OrbitControls.js "$dest"/
cp "$three"/LICENSE "$dest"/three.LICENSE 2>/dev/null || true
