# Sourced by the view tests. npm_tools installs tests/view/js's npm packages (package-lock.json pinned) into a
# folder of the build shared by the tests, once, under a lock (ctest -j runs them side by side); it exits 77
# (ctest: skipped) when node or npm is missing or the registry is unreachable. view_port is below.
npm_tools() {  # npm_tools SOURCE_DIR DEST_DIR
  local src=$1 dest=$2
  if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
    echo "SKIP: node and npm are not installed (scripts/setup.sh installs them)"
    exit 77
  fi
  mkdir -p "$dest"
  (
    flock 9
    cp "$src"/tests/view/js/package.json "$src"/tests/view/js/package-lock.json "$src"/tests/view/js/*.js "$dest"/
    if ! cmp -s "$src"/tests/view/js/package-lock.json "$dest"/node_modules/.adit-lock 2>/dev/null; then
      if ! (cd "$dest" && timeout 300 npm ci --no-audit --no-fund --silent >npm.log 2>&1); then
        echo "SKIP: npm could not install the test's packages (no network?):"
        tail -5 "$dest"/npm.log
        exit 77
      fi
      cp "$src"/tests/view/js/package-lock.json "$dest"/node_modules/.adit-lock
    fi
  ) 9>"$dest".lock || exit $?
}

# The port `adit view --port 0` printed into its log (waits up to TRIES x 0.2 s); fails the test without one.
view_port() {  # view_port LOG_FILE [TRIES]
  local log=$1 tries=${2:-50} port=""
  for _ in $(seq "$tries"); do
    port=$(sed -n 's|.*http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$log" | head -1)
    [ -n "$port" ] && break
    sleep 0.2
  done
  [ -n "$port" ] || { echo "FAIL: adit view did not start" >&2; cat "$log" >&2; exit 1; }
  echo "$port"
}
