#!/usr/bin/env bash
# Reordering on the bus: the simulated live pipeline (launch/sim.launch.yaml) twice in a private network
# namespace, once in order and once with REORDER_PERCENT (1) of the multicast datagrams arriving after the next
# 1 to 4 (tests/faults/reorder_queue.cpp behind an iptables NFQUEUE rule: the kernel has no netem). Datagrams,
# not IP fragments: the INPUT hook sees them reassembled. Checks: no process restarts or stops publishing
# STATUS, the run ends as planned, sweeps still arrive, and the APE of ODOM_MAPPED against the simulator's
# ground truth stays within 20 % (+2 cm for run-to-run noise at real time) of the in-order run.
#   packet_reorder.sh <bin_dir> <source_dir>  env: REORDER_PERCENT (1), MAX_DELAY (4), MTU (1500), DURATION (40), WORLD
source "$(dirname "$0")/common.sh" "$@"
PERCENT=${REORDER_PERCENT:-1} DURATION=${DURATION:-40} WORLD=${WORLD:-roadway-straight}
ip link set lo mtu "${MTU:-1500}"
sysctl -qw net.ipv4.ipfrag_time=2 net.ipv4.ipfrag_high_thresh=33554432  # as packet_loss.sh and the deployment notes
if ! command -v iptables > /dev/null; then echo "SKIP: iptables (Debian package iptables) is not installed"; exit 77; fi
if ! err=$(iptables -A INPUT -d 224.0.0.0/4 -j NFQUEUE --queue-num 7 --queue-bypass 2>&1); then
  echo "SKIP: no NFQUEUE target here (iptables: $err)"; exit 77
fi
iptables -D INPUT -d 224.0.0.0/4 -j NFQUEUE --queue-num 7 --queue-bypass

run in_order
expect "in-order run: exit code" "$LAUNCH_RC" == 0
start_reorder "$PERCENT" -d 224.0.0.0/4
run reordered
stop_reorder "datagrams"
expect "reordered run: exit code" "$LAUNCH_RC" == 0

expect_run_survived reordered in_order "$PERCENT % reordered"
sweeps=$((DURATION * 10)) arrived=$ARRIVED clean_ape=$BASELINE_APE reordered_ape=$RUN_APE
echo "figure: $PERCENT % of datagrams overtaken by 1-${MAX_DELAY:-4} later ones (MTU ${MTU:-1500}): $arrived of $sweeps sweeps arrived (in order: $(fact "$WORK/in_order.facts" outputs STATUS_FEATURE)), lost_input $(fact "$WORK/reordered.facts" counter STATUS_FEATURE lost_input) (in order: $(fact "$WORK/in_order.facts" counter STATUS_FEATURE lost_input)) and time_backwards $(fact "$WORK/reordered.facts" counter STATUS_FEATURE time_backwards) at the feature stage; APE rmse $reordered_ape m vs $clean_ape m in order"
exit $failed
