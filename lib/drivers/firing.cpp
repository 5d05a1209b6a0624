#include "drivers/firing.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace adit::drivers {

const char* counterName(PacketStatus status) {
  switch (status) {
    case PacketStatus::kOk: return "ok";
    case PacketStatus::kWrongSize: return "wrong_size";
    case PacketStatus::kBadMagic: return "bad_magic";
    case PacketStatus::kBadBlockFlag: return "bad_block_flag";
    case PacketStatus::kBadAzimuth: return "bad_azimuth";
    case PacketStatus::kBadTimestamp: return "bad_timestamp";
    case PacketStatus::kUnknownProduct: return "unknown_product";
    case PacketStatus::kUnknownReturnMode: return "unknown_return_mode";
  }
  return "unknown";
}

BeamTable BeamTable::fromElevationsDeg(const std::array<double, kBeams>& elevation_deg) {
  BeamTable t;
  for (int i = 0; i < kBeams; ++i) {
    const double e = elevation_deg[i];
    if (!std::isfinite(e) || e < -90.0 || e > 90.0)
      throw std::invalid_argument("lidar driver: elevation of laser " + std::to_string(i) + " is " +
                                  std::to_string(e) + " deg, not within [-90, 90]");
    t.cos_elevation[i] = static_cast<float>(std::cos(e * M_PI / 180.0));
    t.sin_elevation[i] = static_cast<float>(std::sin(e * M_PI / 180.0));
  }
  std::array<int, kBeams> order{};
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return elevation_deg[a] < elevation_deg[b]; });
  for (int r = 0; r < kBeams; ++r) t.ring[order[r]] = static_cast<std::uint16_t>(r);
  return t;
}

Eigen::Vector3f BeamTable::point(double range_m, double azimuth_deg, int laser) const {
  const double a = azimuth_deg * M_PI / 180.0;
  const double horizontal = range_m * cos_elevation[laser];
  return {static_cast<float>(horizontal * std::cos(a)), static_cast<float>(-horizontal * std::sin(a)),
          static_cast<float>(range_m * sin_elevation[laser])};
}

msg::FiringTable firingTable(const BeamTable& beams, std::int64_t firing_ns) {
  msg::FiringTable t;
  t.ring_offset_ns.assign(kBeams, 0);
  for (int laser = 0; laser < kBeams; ++laser)
    t.ring_offset_ns[beams.ring[laser]] = static_cast<std::int32_t>(laser * firing_ns);
  return t;
}

void resetPacket(DecodedPacket& packet, SensorClock clock) {
  std::vector<Firing> firings = std::move(packet.firings);
  firings.clear();
  packet = DecodedPacket{};
  packet.clock = clock;
  packet.firings = std::move(firings);
}

double wrapAzimuthCentiDeg(double centi_deg) {
  double a = std::fmod(centi_deg, 36000.0);
  if (a < 0) a += 36000.0;
  return a;
}

}  // namespace adit::drivers
