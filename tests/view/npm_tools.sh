# Sourced by the view tests: installs tests/view/js's npm packages (package-lock.json pinned) into a folder
# of the build shared by the tests, once, under a lock (ctest -j runs them side by side). Exits 77 (ctest:
# skipped) when node or npm is missing or the registry is unreachable.
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
