#!/usr/bin/env bash
# Signed commands through real processes over UDP multicast (a private network namespace): an
# adit-loop-closer started with --command-key obeys `adit command save_map --key` with that key and nothing
# else (unsigned, another key); a key file others may read stops it at start.
#   signed_commands.sh <bin_dir>
set -uo pipefail
BIN=$1
WORK=$(mktemp -d)
trap 'kill $CLOSER 2>/dev/null; rm -rf "$WORK"' EXIT
CLOSER=
export LCM_DEFAULT_URL='udpm://239.255.76.67:7667?ttl=0'
failed=0
fail() { echo "FAIL: $*"; failed=1; }
# Waits up to 10 s for a file: the command crosses the bus and the closer's thread.
appears() { for _ in $(seq 100); do [ -e "$1" ] && return 0; sleep 0.1; done; return 1; }

"$BIN/adit" command keygen "$WORK/op.key" || fail "keygen"
"$BIN/adit" command keygen "$WORK/other.key" || fail "keygen"
"$BIN/adit" command keygen "$WORK/op.key" 2>/dev/null && fail "keygen overwrote a key"

cp "$WORK/op.key" "$WORK/open.key" && chmod 644 "$WORK/open.key"
mkdir -p "$WORK/open-run"
out=$("$BIN/adit-loop-closer" --run-dir "$WORK/open-run" --command-key "$WORK/open.key" 2>&1)
status=$?
[ $status -eq 2 ] && grep -q "open.key" <<<"$out" || fail "a world-readable key did not stop the process ($status: $out)"

mkdir -p "$WORK/run"
ADIT_COMMAND_KEY="$WORK/op.key" "$BIN/adit-loop-closer" --run-dir "$WORK/run" >"$WORK/closer.log" 2>&1 &
CLOSER=$!
sleep 1
"$BIN/adit" command save_map unsigned
"$BIN/adit" command save_map --key "$WORK/other.key" other_key
"$BIN/adit" command save_map --key "$WORK/op.key" signed
appears "$WORK/run/signed.tum" && echo "ok: the signed command was obeyed" || fail "the signed command was not obeyed"
# A second signed command (a new counter) is obeyed too; replayed and altered ones: test_commands.cpp.
"$BIN/adit" command save_map --key "$WORK/op.key" signed_again
appears "$WORK/run/signed_again.tum" || fail "a second signed command was not obeyed"
for f in unsigned other_key; do [ -e "$WORK/run/$f.tum" ] && fail "$f was obeyed"; done
grep -q "command_unsigned\|not signed" "$WORK/closer.log" || fail "the unsigned command was not reported"
grep -q "signature does not match" "$WORK/closer.log" || fail "the command of another key was not reported"
kill "$CLOSER"; wait "$CLOSER" 2>/dev/null
[ $failed -eq 0 ] && echo "signed commands: ok"
exit $failed
