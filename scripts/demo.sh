#!/usr/bin/env bash
# Install what is missing, build, and run the simulated roadway demo: a robot drives 1.2 laps of a 510 m
# roadway loop with a VLP-16 and an IMU; the whole pipeline maps it; the report compares the result with the
# simulator's ground truth. Run as root on Debian 12. Extra arguments go to `adit demo` (see --help).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
exec build/bin/adit demo "$@"
