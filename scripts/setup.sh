#!/usr/bin/env bash
# Install every Debian package adit needs (idempotent, non-interactive, quiet when nothing is missing),
# then configure and build into build/ (Release, -j2). Run as root on Debian 12.
#   scripts/setup.sh            install + build
#   scripts/setup.sh --no-build install only
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake pkg-config git
  liblcm-dev liblcm-bin liblcm-java libglib2.0-dev
  libeigen3-dev libceres-dev libpcl-dev
  libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev libnanoflann-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  openjdk-17-jdk-headless openjdk-17-jre libjchart2d-java
  python3-numpy python3-matplotlib
  libssl-dev libbz2-dev liblz4-dev libzstd-dev
  iproute2 util-linux nftables iptables libnetfilter-queue-dev curl
)
# Only the browser and MCAP tests use these (they skip without them). They are checked by command, not by
# package: Node.js from another vendor (NodeSource's nodejs bundles npm) conflicts with Debian's npm package, and
# a tool that is already on the PATH is good enough. A failed install is a warning, never a failed setup.
OPTIONAL_TOOLS=(node:nodejs npm:npm chromium:chromium)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if ((${#missing[@]})); then
  echo "setup: installing ${#missing[@]} missing package(s): ${missing[*]}"
  if [ "$(id -u)" -ne 0 ]; then
    echo "setup: packages are missing and this is not root; run as root (or install them yourself)" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

optional=()
for entry in "${OPTIONAL_TOOLS[@]}"; do
  command -v "${entry%%:*}" >/dev/null 2>&1 || optional+=("${entry#*:}")
done
if ((${#optional[@]})) && [ "$(id -u)" -eq 0 ]; then
  echo "setup: installing optional test tool package(s): ${optional[*]}"
  export DEBIAN_FRONTEND=noninteractive
  ((${#missing[@]})) || apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${optional[@]}" >/dev/null ||
    echo "setup: warning: could not install ${optional[*]}; the browser and MCAP tests will be skipped" >&2
fi

[ "${1:-}" = "--no-build" ] && exit 0

cmake -S . -B build -DCMAKE_BUILD_TYPE="${ADIT_BUILD_TYPE:-Release}" -DADIT_STRICT=ON >/dev/null
cmake --build build -j"${ADIT_JOBS:-2}"
