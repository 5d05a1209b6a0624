#!/usr/bin/env bash
# Packet loss and reordering on the sensors' links, where a robot loses packets: the simulated pipeline with
# its lidar on its own UDP link (launch/sim-packets.launch.yaml: `adit sim --lidar-udp` sends VLP-16 data
# packets, adit-lidar-bridge decodes them), twice in a private network namespace: once clean, once with
# LOSS_PERCENT (5) of the lidar's packets and of the IMU's messages dropped at random (nftables) and
# REORDER_PERCENT (1) of the lidar's packets overtaken by 1-4 later ones (reorder-queue behind an iptables
# NFQUEUE rule; left out, and said so, where the kernel has no NFQUEUE). The stages' own bus is not touched:
# it never leaves the computer (ttl=0; packet_loss.sh measures what loss there would do).
# Checks: the losses are counted on STATUS (the bridge's lost_packets, lost_input of IMU at the stages), no
# process restarts or stops publishing STATUS, the run ends as planned, and the APE of ODOM_MAPPED against the
# simulator's ground truth stays within 20 % (+2 cm for run-to-run noise at real time) of the clean run.
#   sensor_link_loss.sh <bin_dir> <source_dir>  env: LOSS_PERCENT (5), REORDER_PERCENT (1), DURATION (40), WORLD
source "$(dirname "$0")/common.sh" "$@"
LOSS=${LOSS_PERCENT:-5} REORDER=${REORDER_PERCENT:-1} DURATION=${DURATION:-40} WORLD=${WORLD:-roadway-straight}
LAUNCH_FILE=$ROOT/launch/sim-packets.launch.yaml
PORT=2368
if ! command -v nft > /dev/null; then echo "SKIP: nft (Debian package nftables) is not installed"; exit 77; fi

run clean
expect "clean run: exit code" "$LAUNCH_RC" == 0

# The lidar's packets by their port; the IMU's LCM datagrams by their channel name, which LCM writes after its
# 8-byte header (magic, sequence number) at the start of the UDP payload: "IMU\0" at payload byte 8.
threshold=$(awk -v p="$LOSS" 'BEGIN { printf "%d", p * 1000 }')
nft add table ip lossy
nft add chain ip lossy pre '{ type filter hook prerouting priority -450; }'
nft add rule ip lossy pre udp dport $PORT numgen random mod 100000 "<" "$threshold" counter drop
nft add rule ip lossy pre udp dport $PORT counter
nft add rule ip lossy pre ip daddr 224.0.0.0/4 @th,128,32 0x494d5500 numgen random mod 100000 "<" "$threshold" counter drop
nft add rule ip lossy pre ip daddr 224.0.0.0/4 @th,128,32 0x494d5500 counter
start_reorder "$REORDER" -p udp --dport $PORT
run lossy
stop_reorder "lidar packets"
expect "lossy run: exit code" "$LAUNCH_RC" == 0
nft list chain ip lossy pre | grep counter | sed 's/^\s*/nft: /'
# nft's counters: dropped and passed, lidar and IMU, in the order the rules were added.
mapfile -t nft_packets < <(nft list chain ip lossy pre | awk '/counter/ { for (i = 1; i < NF; ++i) if ($i == "packets") print $(i + 1) }')
lidar_dropped=${nft_packets[0]} lidar_passed=${nft_packets[1]} imu_dropped=${nft_packets[2]} imu_passed=${nft_packets[3]}
expect "lidar packets dropped" "$lidar_dropped" ">" 0
expect "IMU messages dropped" "$imu_dropped" ">" 0

lost_packets=$(fact "$WORK/lossy.facts" counter STATUS_LIDAR_BRIDGE lost_packets)
late=$(fact "$WORK/lossy.facts" counter STATUS_LIDAR_BRIDGE time_backwards)
# The bridge sees the holes in the stamps: every dropped packet and every one overtaken (skipped as late), less
# those in holes long enough to count as packet_gap, and the few of the run's first and last moments. (More is
# possible on a loaded machine: packets the bridge's socket buffer dropped. The count's exactness is the
# drivers unit test's.)
expect "lost packets counted by the lidar bridge (dropped $lidar_dropped + late $late)" "$lost_packets" ">=" \
  "$(( (lidar_dropped + late) * 9 / 10 ))"
imu_lost=$(fact "$WORK/lossy.facts" counter STATUS_FEATURE lost_input)
expect "lost inputs counted by the feature stage" "$imu_lost" ">" 0
expect "sweeps published by the lidar bridge (clean: $(fact "$WORK/clean.facts" outputs STATUS_LIDAR_BRIDGE))" \
  "$(fact "$WORK/lossy.facts" outputs STATUS_LIDAR_BRIDGE)" ">=" "$(( $(fact "$WORK/clean.facts" outputs STATUS_LIDAR_BRIDGE) - 2 ))"
expect_run_survived lossy clean "$LOSS % loss on the sensors' links"
echo "figure: $LOSS % of the lidar's packets ($lidar_dropped of $((lidar_dropped + lidar_passed))) and of the IMU's messages ($imu_dropped of $((imu_dropped + imu_passed))) lost, reordering $REORDER_STATE ($REORDER %): the bridge counted $lost_packets lost packets ($(fact "$WORK/lossy.facts" counter STATUS_LIDAR_BRIDGE packet_gap) longer gaps) and published $ARRIVED sweeps to the feature stage (clean: $(fact "$WORK/clean.facts" outputs STATUS_FEATURE)), $late overtaken ones skipped as late, lost_input $imu_lost at the feature stage; APE rmse $RUN_APE m vs $BASELINE_APE m clean"
exit $failed
