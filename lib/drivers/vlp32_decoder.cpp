#include "drivers/vlp32_decoder.hpp"

#include "drivers/packet_bytes.hpp"
#include "drivers/vlp16_decoder.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace adit::drivers {
namespace {

constexpr int kBlocks = kVelodyneBlocks;
constexpr std::size_t kBlockBytes = 100;
constexpr double kMaxBlockGapCentiDeg = 1000.0;  // as vlp16_decoder.cpp

// VLP-32C manual table 9-2: elevation and horizontal offset delta by laser id (packet order).
constexpr double kVlp32cElevation[kBeams32] = {-25,    -1,     -1.667, -15.639, -11.31, 0,     -0.667, -8.843,
                                               -7.254, 0.333,  -0.333, -6.148,  -5.333, 1.333, 0.667,  -4,
                                               -4.667, 1.667,  1,      -3.667,  -3.333, 3.333, 2.333,  -2.667,
                                               -3,     7,      4.667,  -2.333,  -2,     15,    10.333, -1.333};
constexpr double kVlp32cDelta[kBeams32] = {1.4, -4.2, 1.4, -1.4, 1.4, -1.4, 4.2, -1.4, 1.4, -4.2, 1.4,
                                           -1.4, 4.2, -1.4, 4.2, -1.4, 1.4, -4.2, 1.4, -4.2, 4.2, -1.4,
                                           1.4, -1.4, 1.4, -1.4, 1.4, -4.2, 4.2, -1.4, 1.4, -1.4};

Velodyne32Spec makeVlp32c() {
  Velodyne32Spec s;
  for (int i = 0; i < kBeams32; ++i)
    s.lasers[static_cast<std::size_t>(i)] = {kVlp32cElevation[i], kVlp32cDelta[i], (i / 2) * 2304};
  s.sequence_ns = 55296;
  s.distance_unit_m = 0.004;
  s.product_id = 0x28;
  return s;
}

Velodyne32Spec makeHdl32e() {
  Velodyne32Spec s;
  for (int i = 0; i < kBeams32; ++i) {
    // Even ids: -30.67 + 1.33 k (the lower half), odd ids: -9.33 + 1.33 k (the upper half), k = id / 2; the
    // manual's table rounds thirds of a degree to 0.01.
    const double e = (i % 2 == 0 ? -92.0 / 3.0 : -28.0 / 3.0) + (4.0 / 3.0) * (i / 2);
    s.lasers[static_cast<std::size_t>(i)] = {std::round(e * 100.0) / 100.0, 0.0, i * 1152};
  }
  s.sequence_ns = 46080;
  s.distance_unit_m = 0.002;
  s.product_id = 0x21;
  return s;
}

std::array<std::uint16_t, kBeams32> ringsOf(const Velodyne32Spec& s) {
  std::array<int, kBeams32> order{};
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&s](int a, int b) {
    return s.lasers[static_cast<std::size_t>(a)].elevation_deg < s.lasers[static_cast<std::size_t>(b)].elevation_deg;
  });
  std::array<std::uint16_t, kBeams32> ring{};
  for (int r = 0; r < kBeams32; ++r) ring[static_cast<std::size_t>(order[static_cast<std::size_t>(r)])] = static_cast<std::uint16_t>(r);
  return ring;
}

}  // namespace

const Velodyne32Spec& velodyne32Spec(Velodyne32 model) {
  static const Velodyne32Spec vlp32c = makeVlp32c(), hdl32e = makeHdl32e();
  return model == Velodyne32::kVlp32c ? vlp32c : hdl32e;
}

msg::FiringTable firingTable32(Velodyne32 model) {
  const Velodyne32Spec& s = velodyne32Spec(model);
  const auto ring = ringsOf(s);
  msg::FiringTable t;
  t.ring_offset_ns.assign(kBeams32, 0);
  for (std::size_t i = 0; i < kBeams32; ++i) t.ring_offset_ns[ring[i]] = static_cast<std::int32_t>(s.lasers[i].offset_ns);
  return t;
}

Vlp32Decoder::Vlp32Decoder(Velodyne32 model, std::vector<std::uint8_t> accept_products)
    : spec_(velodyne32Spec(model)), accept_products_(std::move(accept_products)), ring_(ringsOf(spec_)) {
  for (std::size_t i = 0; i < kBeams32; ++i) {
    const double e = spec_.lasers[i].elevation_deg * M_PI / 180.0;
    cos_el_[i] = static_cast<float>(std::cos(e));
    sin_el_[i] = static_cast<float>(std::sin(e));
  }
}

PacketStatus Vlp32Decoder::decode(const std::uint8_t* data, std::size_t size, DecodedPacket& out) const {
  std::uint16_t azimuth[kBlocks];
  const PacketStatus status = readVelodyneFrame(data, size, spec_.product_id, accept_products_, azimuth, out);
  if (status != PacketStatus::kOk) return status;
  const int returns = out.dual_return ? 2 : 1;
  const int groups = kBlocks / returns;
  out.firings.reserve(static_cast<std::size_t>(kBlocks * kBeams32));
  for (int g = 0; g < groups; ++g) {
    const int b = g * returns;
    double gap = b + returns < kBlocks ? wrapAzimuthCentiDeg(static_cast<double>(azimuth[b + returns]) - azimuth[b])
                                       : wrapAzimuthCentiDeg(static_cast<double>(azimuth[b]) - azimuth[b - returns]);
    if (gap > kMaxBlockGapCentiDeg) gap = 0.0;
    for (std::size_t laser = 0; laser < kBeams32; ++laser) {
      const Laser32& l = spec_.lasers[laser];
      // The head's azimuth at the firing (what cuts sweeps), and the beam's own, offset by delta (where the
      // point is): cutting on the beam azimuth would flip back and forth across the cut within one sequence.
      const double head_az = wrapAzimuthCentiDeg(azimuth[b] + gap * static_cast<double>(l.offset_ns) /
                                                                  static_cast<double>(spec_.sequence_ns)) * 0.01;
      const double a = (head_az + l.azimuth_offset_deg) * M_PI / 180.0;
      std::uint16_t first_raw = 0;
      for (int r = 0; r < returns; ++r) {
        const std::uint8_t* point = data + (b + r) * kBlockBytes + 4 + laser * 3;
        const std::uint16_t raw = readLe16(point);
        if (r == 0) first_raw = raw;
        Firing f;
        f.offset_ns = g * spec_.sequence_ns + l.offset_ns;
        f.azimuth_deg = static_cast<float>(head_az);
        f.ring = ring_[laser];
        f.intensity = point[2];
        f.has_return = raw != 0 && !(r == 1 && raw == first_raw);
        if (f.has_return) {
          const double range = raw * spec_.distance_unit_m, h = range * cos_el_[laser];
          f.p = Eigen::Vector3f(static_cast<float>(h * std::cos(a)), static_cast<float>(-h * std::sin(a)),
                                static_cast<float>(range * sin_el_[laser]));
        }
        out.firings.push_back(f);
      }
    }
  }
  // Pairs fire together: keep the firings in non-decreasing time (they are, by laser order).
  out.duration_ns = out.firings.back().offset_ns;
  return PacketStatus::kOk;
}

}  // namespace adit::drivers
