#!/usr/bin/env bash
# Runs a command in a private network namespace whose loopback carries UDP multicast, so tests over real UDP
# neither need nor touch the host's routes and never reach another machine:
#   netns.sh [--mount] COMMAND [ARGS...]
# --mount also gives the command its own mount namespace (tests that mount a tmpfs).
# As root: `unshare -n`; otherwise a user namespace, `unshare -rn`. Where neither is allowed (an unprivileged
# container, a chroot without CAP_SYS_ADMIN) it prints why and exits 77, which the tests register as ctest's
# SKIP_RETURN_CODE: skipped with the reason, not failed. Inside, ADIT_IN_NETNS=1.
set -euo pipefail
flags=-n
if [ "${1:-}" = --mount ]; then flags=-nm; shift; fi
if [ "$(id -u)" != 0 ]; then flags=-r${flags#-}; fi
if ! err=$(unshare "$flags" true 2>&1); then
  echo "SKIP: cannot create a private network namespace (unshare $flags: ${err:-failed}); this test needs root or user namespaces"
  exit 77
fi
if ! command -v ip >/dev/null; then
  echo "SKIP: 'ip' (Debian package iproute2) is not installed"
  exit 77
fi
exec unshare "$flags" env ADIT_IN_NETNS=1 bash -c \
  'ip link set lo up multicast on && ip route add 224.0.0.0/4 dev lo && exec "$@"' netns "$@"
