// A recorded capture (pcap / pcapng) of a VLP-16 or RS-16 as a message source for adit-lidar-bridge and
// `adit import pcap`: the sweeps of CaptureLidarReader (which see), encoded as the live driver encodes them.
#pragma once

#include "drivers/udp_lidar_source.hpp"
#include "runtime/source.hpp"

#include <memory>
#include <string>

namespace adit::sources {

// Throws io::ReadError if the file cannot be opened or is not a capture, std::invalid_argument on a bad config.
std::unique_ptr<runtime::MessageSource> makePcapLidarSource(const std::string& path,
                                                            const drivers::UdpLidarConfig& config);

}  // namespace adit::sources
