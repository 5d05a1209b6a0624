// A live VLP-16 / RS-16 as an adit::runtime::MessageSource: receives the sensor's UDP data packets, decodes
// them and yields one encoded adit::point_cloud_t per sweep. For adit-lidar-bridge, run with rate 0
// (messages are due as soon as a sweep is complete).
//
// Config keys (YAML, under lidar_driver.) and defaults: see UdpLidarConfig. Deployment: the kernel caps the
// socket buffer at net.core.rmem_max (212992 on stock Debian); set sysctl -w net.core.rmem_max=8388608.
#pragma once

#include "core/config.hpp"
#include "drivers/lidar_stream.hpp"
#include "runtime/source.hpp"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace adit::drivers {

struct UdpLidarConfig {
  // lidar_driver.model: "vlp16", "rs16", "vlp32c" or "hdl32e" (the 32-beam heads: nominal tables only).
  std::string model = "vlp16";
  // lidar_driver.bind_address: IPv4 address to listen on; 0.0.0.0 = all interfaces (the sensors' factory
  // setting broadcasts / sends to the host, either reaches it).
  std::string bind_address = "0.0.0.0";
  // lidar_driver.port: data port; 0 = the model's (VLP-16 2368, RS-16 MSOP 6699).
  int port = 0;
  // lidar_driver.recv_buffer_bytes: socket receive buffer asked for. 8 MiB ~ 3 s of VLP-16 packets, so a
  // stalled consumer loses nothing; the kernel grants at most net.core.rmem_max.
  int recv_buffer_bytes = 8 * 1024 * 1024;
  // lidar_driver.channel: LCM channel of the sweeps.
  std::string channel = "LIDAR_POINTS";
  // lidar_driver.sensor_name: LidarScan::sensor / point_cloud_t.sensor; "" = the model name.
  std::string sensor_name;
  // lidar_driver.time_source: "sensor" (the packets' own stamps mapped onto the host clock by a filtered
  // offset and drift: exact firing spacing, immune to network jitter), "utc" (the stamps as they are: a
  // GPS/PPS-synchronised sensor and a host on UTC) or "host" (kernel receive time).
  std::string time_source = "sensor";
  // lidar_driver.max_clock_jump_s: a sensor clock step larger than this re-anchors on the host clock (s).
  double max_clock_jump_s = 1.0;
  // lidar_driver.transport_delay_s: sensor time: the fixed delay from a packet's last firing to its host
  // receive time (the sensor's send, the wire), subtracted; one-way timing cannot measure it. 0 = unknown
  // (tens of microseconds on a direct Ethernet link).
  double transport_delay_s = 0.0;
  // lidar_driver.cut_azimuth_deg, max_sweep_duration_s, max_firing_gap_s: see SweepAssemblerConfig.
  double cut_azimuth_deg = 180.0;
  double max_sweep_duration_s = 0.25;
  double max_firing_gap_s = 0.010;
  // lidar_driver.vertical_angles_deg: 16 elevations (deg) by laser id in packet order, e.g. an RS-16's
  // DIFOP calibration; empty = the model's nominal table.
  std::vector<double> vertical_angles_deg;
  // lidar_driver.accept_product_ids: VLP-16 only: factory product ids (byte 1205, decimal) to decode as
  // VLP-16 packets besides 34 (0x22, VLP-16) and 0 (firmware before 3.0.29). Some units in the field announce
  // another product (e.g. 36 = 0x24, Puck Hi-Res) while sending VLP-16 packets; without this every packet
  // of such a unit is dropped as unknown_product.
  std::vector<int> accept_product_ids;
  // lidar_driver.dual_return: RS-16 only: decode dual-return packets from the start (a DIFOP packet, if the
  // recording or the network holds one, says which mode the sensor is in and overrides this).
  bool dual_return = false;
  // lidar_driver.difop_port: RS-16 only: the port of the DIFOP packets, live and in recordings (0 = 7788,
  // -1 = ignore them). Live, a port another program holds is a warning: the configured table is used.
  int difop_port = 0;
  // lidar_driver.sensor_address: recordings (pcap): only datagrams from this IPv4 address are the sensor's;
  // "" = the first host that sends a packet of the model's size to the data port.
  std::string sensor_address;
  // lidar_driver.idle_timeout_s: next() reports the end after this long without a packet (s); 0 = wait
  // for the sensor forever (stops only on SIGINT/SIGTERM).
  double idle_timeout_s = 0.0;
};

// Reads the lidar_driver.* keys; throws std::runtime_error on a value that does not parse.
UdpLidarConfig udpLidarConfigFrom(const Config& c);

// Checks names and numbers (model, time source, port range, angle table); throws std::invalid_argument.
LidarStreamConfig streamConfigOf(const UdpLidarConfig& config);
// The UDP port the config listens on (its port, or the model's default).
std::uint16_t dataPortOf(const UdpLidarConfig& config);

// Binds the socket now (throws std::runtime_error if it cannot, std::invalid_argument on a bad config).
// next() blocks until a sweep is complete; it returns false on SIGINT/SIGTERM (runtime::stopRequested),
// when `stop` (if given) returns true, or after idle_timeout_s without packets.
std::unique_ptr<runtime::MessageSource> makeUdpLidarSource(const UdpLidarConfig& config,
                                                           std::function<bool()> stop = {});

}  // namespace adit::drivers
