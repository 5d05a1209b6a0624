#include "clouds.hpp"

#include <cmath>
#include <cstring>

namespace adit::test {
namespace {

constexpr int kRings = 16;

// A point on beam `ring` (elevation -15..+15 deg by 2) at column `c`, range varying with the salt.
Eigen::Vector3f beamPoint(int ring, int c, int columns, unsigned salt) {
  const double elevation = (-15.0 + 2.0 * ring) * M_PI / 180.0;
  const double azimuth = 2.0 * M_PI * c / columns;
  const double range = 4.0 + 0.37 * ((c * 7 + ring * 13 + static_cast<int>(salt)) % 61);
  return Eigen::Vector3f(static_cast<float>(range * std::cos(elevation) * std::cos(azimuth)),
                         static_cast<float>(range * std::cos(elevation) * std::sin(azimuth)),
                         static_cast<float>(range * std::sin(elevation)));
}

template <typename T>
void store(Bytes& b, std::size_t at, T v) {
  std::memcpy(b.data() + at, &v, sizeof(T));
}

}  // namespace

TestCloud velodyneCloud(std::uint32_t sec, std::uint32_t nsec, int columns, unsigned salt) {
  constexpr std::uint32_t step = 22;
  TestCloud t;
  Bytes data(std::size_t{step} * kRings * columns);
  std::size_t i = 0;
  for (int c = 0; c < columns; ++c)
    for (int r = 0; r < kRings; ++r, ++i) {
      LidarPoint p;
      p.p = beamPoint(r, c, columns, salt);
      p.intensity = static_cast<float>((c + r) % 100);
      p.ring = static_cast<std::uint16_t>(r);
      p.dt = -0.1f + 0.1f * static_cast<float>(c + 1) / static_cast<float>(columns);  // last column at 0
      const std::size_t at = i * step;
      store(data, at, p.p.x());
      store(data, at + 4, p.p.y());
      store(data, at + 8, p.p.z());
      store(data, at + 12, p.intensity);
      store(data, at + 16, p.ring);
      store(data, at + 18, p.dt);
      t.expected.push_back(p);
    }
  t.message = pointCloud2(sec, nsec, {{"x", 0, 7}, {"y", 4, 7}, {"z", 8, 7}, {"intensity", 12, 7}, {"ring", 16, 4}, {"time", 18, 7}},
                          step, data);
  // The times are relative to the stamp, the largest is 0: the last firing is the stamp.
  float max_dt = -1.0f;
  for (const LidarPoint& p : t.expected) max_dt = std::max(max_dt, p.dt);
  for (LidarPoint& p : t.expected) p.dt = static_cast<float>(static_cast<double>(p.dt) - static_cast<double>(max_dt));
  t.expected_utime = std::int64_t{sec} * 1000000 + (nsec + 500) / 1000 + std::llround(static_cast<double>(max_dt) * 1e6);
  return t;
}

TestCloud ousterCloud(std::uint32_t sec, std::uint32_t nsec, int columns, unsigned salt, std::uint32_t row_padding) {
  constexpr std::uint32_t step = 48;
  TestCloud t;
  Bytes data(std::size_t{step} * kRings * columns, 0xCD);  // padding bytes hold garbage
  std::vector<std::uint32_t> ns;
  for (int row = 0; row < kRings; ++row)  // row 0 = top beam
    for (int c = 0; c < columns; ++c) {
      const int ring = kRings - 1 - row;
      LidarPoint p;
      p.p = beamPoint(ring, c, columns, salt);
      p.intensity = static_cast<float>(c % 250) + 0.5f;
      p.ring = static_cast<std::uint16_t>(ring);
      const std::uint32_t t_ns = static_cast<std::uint32_t>(c) * (100000000u / static_cast<std::uint32_t>(columns)) + 17;
      const std::size_t at = (std::size_t{static_cast<std::size_t>(row)} * columns + c) * step;
      store(data, at, p.p.x());
      store(data, at + 4, p.p.y());
      store(data, at + 8, p.p.z());
      store(data, at + 16, p.intensity);
      store(data, at + 20, t_ns);
      store(data, at + 24, std::uint16_t{99});
      store(data, at + 26, static_cast<std::uint8_t>(row));
      store(data, at + 28, std::uint16_t{5});
      store(data, at + 32, static_cast<std::uint32_t>(p.p.norm() * 1000));
      ns.push_back(t_ns);
      t.expected.push_back(p);
    }
  t.message = pointCloud2(sec, nsec,
                          {{"x", 0, 7}, {"y", 4, 7}, {"z", 8, 7}, {"intensity", 16, 7}, {"t", 20, 6}, {"reflectivity", 24, 4},
                           {"ring", 26, 2}, {"ambient", 28, 4}, {"range", 32, 6}},
                          step, data, kRings, row_padding);
  const std::uint32_t max_ns = *std::max_element(ns.begin(), ns.end());
  for (std::size_t i = 0; i < ns.size(); ++i)
    t.expected[i].dt = static_cast<float>(ns[i] * 1e-9 - max_ns * 1e-9);
  t.expected_utime = std::int64_t{sec} * 1000000 + (nsec + 500) / 1000 + std::llround(max_ns * 1e-3);
  return t;
}

}  // namespace adit::test
