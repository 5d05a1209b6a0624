#!/usr/bin/env bash
# Install what is missing, build everything, and run the whole test suite (unit + integration).
# Run as root on Debian 12. CI runs exactly this (.ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
ctest --test-dir build --output-on-failure --timeout 900 -j"${ADIT_JOBS:-2}"
