#include "msg/sweep_codec.hpp"

#include "msg/convert.hpp"
#include "msg/sweep_header.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace adit::msg {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;
constexpr double kAzimuthUnit = kTwoPi / 65536.0;       // rad per azimuth count (per-point layout)
constexpr double kColumnAzimuthUnit = kTwoPi / 4294967296.0;  // rad per column_azimuth count
constexpr double kElevationUnit = M_PI / 2.0 / 32767.0;  // rad per elevation count
// Columns further apart in time than this belong to different firing sequences (a slot is >= 0.75 us).
constexpr double kColumnTimeTolerance_ns = 300.0;
constexpr int kElevationSamples = 64;

std::int16_t toU16(long v) { return static_cast<std::int16_t>(static_cast<std::uint16_t>(std::clamp(v, 0L, 65535L))); }
double fromU16(std::int16_t v) { return static_cast<double>(static_cast<std::uint16_t>(v)); }
std::int16_t azimuthCount(double az) {
  double a = std::fmod(az, kTwoPi);
  if (a < 0) a += kTwoPi;
  return static_cast<std::int16_t>(static_cast<std::uint16_t>(std::lround(a / kAzimuthUnit) & 0xFFFF));
}
std::int32_t columnAzimuthCount(double az) {
  double a = std::fmod(az, kTwoPi);
  if (a < 0) a += kTwoPi;
  return static_cast<std::int32_t>(static_cast<std::uint32_t>(std::llround(a / kColumnAzimuthUnit) & 0xFFFFFFFFLL));
}
double wrapPi(double a) { return a - kTwoPi * std::floor((a + M_PI) / kTwoPi); }

// Cosine and sine of every angle a 16-bit count of the per-point layout can hold, computed once per process
// (2 x 1 MB, only where such sweeps are decoded): a KITTI sweep's 120k points took two sincos calls each, a
// tenth of the feature process's time. The same doubles as std::cos / std::sin of the angle: same points.
struct CosSin {
  double cos, sin;
};
std::vector<CosSin> cosSinTable(int first_count, int last_count, double unit) {
  std::vector<CosSin> t;
  t.reserve(static_cast<std::size_t>(last_count - first_count + 1));
  for (int c = first_count; c <= last_count; ++c) t.push_back({std::cos(c * unit), std::sin(c * unit)});
  return t;
}
const CosSin& azimuthCosSin(std::int16_t count) {
  static const std::vector<CosSin> table = cosSinTable(0, 65535, kAzimuthUnit);
  return table[static_cast<std::uint16_t>(count)];
}
const CosSin& elevationCosSin(std::int16_t count) {  // count in [-32767, 32767]
  static const std::vector<CosSin> table = cosSinTable(-32767, 32767, kElevationUnit);
  return table[static_cast<std::size_t>(count + 32767)];
}

void fillCommon(const LidarScan& scan, adit::lidar_scan_t& m) {
  m.header = makeHeader(scan.utime, "lidar");
  m.header.seq = scan.seq;
  m.format_version = kSweepFormatVersion;
  m.sensor = scan.sensor;
  m.num_beams = static_cast<std::int16_t>(std::clamp(scan.num_beams, 0, 255));
  m.sweep_duration = scan.sweep_duration;
  m.flags = sweepFlags(scan);
  m.azimuth_rate = 0.0f;
  m.num_columns = 0;
  m.num_returns = 0;
  m.num_points = 0;
}

std::vector<LidarPoint> finitePoints(const LidarScan& scan) {
  std::vector<LidarPoint> out;
  out.reserve(scan.points.size());
  for (const LidarPoint& p : scan.points)
    if (p.p.allFinite() && std::isfinite(p.intensity) && std::isfinite(p.dt)) out.push_back(p);
  return out;
}

float rangeScaleFor(const std::vector<LidarPoint>& points) {
  float max_range = 0.0f;
  for (const LidarPoint& p : points) max_range = std::max(max_range, p.p.norm());
  return std::max(kRangeScale, max_range / 65000.0f);
}

float intensityScaleFor(const std::vector<LidarPoint>& points) {
  float max_i = 0.0f;
  for (const LidarPoint& p : points) max_i = std::max(max_i, p.intensity);
  if (max_i <= 1.0f) return 1.0f / 255.0f;  // KITTI reflectance 0..1
  return max_i <= 255.0f ? 1.0f : max_i / 255.0f;
}

std::uint8_t intensityByte(float intensity, float scale) {
  return static_cast<std::uint8_t>(std::clamp(std::lround(intensity / scale), 0L, 255L));
}

// ---- per-point layout ----

adit::lidar_scan_t encodePoints(const LidarScan& scan, const std::vector<LidarPoint>& points) {
  adit::lidar_scan_t m;
  fillCommon(scan, m);
  m.layout = adit::lidar_scan_t::LAYOUT_POINTS;
  m.range_scale = rangeScaleFor(points);
  m.intensity_scale = intensityScaleFor(points);
  m.ring_elevation.assign(static_cast<std::size_t>(m.num_beams), 0.0f);
  m.ring_offset_ns.assign(static_cast<std::size_t>(m.num_beams), 0);
  const std::size_t n = points.size();
  m.num_returns = m.num_points = static_cast<std::int32_t>(n);
  m.range.resize(n);
  m.intensity.resize(n);
  m.azimuth.resize(n);
  m.elevation.resize(n);
  m.ring.resize(n);
  m.time.resize(n);
  const double duration = std::max(1e-9, static_cast<double>(scan.sweep_duration));
  for (std::size_t i = 0; i < n; ++i) {
    const LidarPoint& p = points[i];
    const double x = p.p.x(), y = p.p.y(), z = p.p.z();
    const double range = std::sqrt(x * x + y * y + z * z);
    m.range[i] = toU16(std::lround(range / m.range_scale));
    m.intensity[i] = intensityByte(p.intensity, m.intensity_scale);
    m.azimuth[i] = azimuthCount(std::atan2(y, x));
    m.elevation[i] = static_cast<std::int16_t>(std::lround(std::atan2(z, std::hypot(x, y)) / kElevationUnit));
    m.ring[i] = static_cast<std::uint8_t>(scan.has_ring ? std::min<int>(p.ring, 255) : 0);
    m.time[i] = scan.has_time ? toU16(std::lround(-static_cast<double>(p.dt) / duration * 65535.0)) : 0;
  }
  return m;
}

// ---- firing-grid layout ----

struct GridColumn {
  double time_ns = 0;     // time of the column's first slot, relative to utime
  double azimuth = 0;     // rad, at the column's time
  std::uint32_t filled = 0;
  std::vector<std::size_t> point_of_ring;  // index into points, SIZE_MAX = no return
};

// The average spin rate (rad/s): the wrapped azimuth steps between consecutive points over the time they span.
double spinRate(const std::vector<LidarPoint>& points, const std::vector<double>& azimuth) {
  double turned = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) turned += wrapPi(azimuth[i] - azimuth[i - 1]);
  const double span = static_cast<double>(points.back().dt) - static_cast<double>(points.front().dt);
  return span > 0 ? turned / span : 0.0;
}

bool encodeGrid(const LidarScan& scan, const std::vector<LidarPoint>& points, const FiringTable& table,
                adit::lidar_scan_t& m) {
  const int beams = table.beams();
  if (points.size() < 2 || beams != scan.num_beams || beams <= 0 || beams > 255 || !scan.has_ring || !scan.has_time)
    return false;
  std::vector<double> azimuth(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) azimuth[i] = std::atan2(points[i].p.y(), points[i].p.x());
  const double rate = spinRate(points, azimuth);
  std::vector<double> elevation_sum(static_cast<std::size_t>(beams), 0.0);
  std::vector<int> elevation_n(static_cast<std::size_t>(beams), 0);
  std::vector<GridColumn> columns;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const LidarPoint& p = points[i];
    if (p.ring >= beams) return false;
    const double offset = table.ring_offset_ns[p.ring];
    const double t = static_cast<double>(p.dt) * 1e9 - offset;
    const double az = azimuth[i] - rate * offset * 1e-9;
    GridColumn* c = columns.empty() ? nullptr : &columns.back();
    if (!c || std::fabs(t - c->time_ns) > kColumnTimeTolerance_ns || c->point_of_ring[p.ring] != SIZE_MAX) {
      GridColumn next;
      next.time_ns = t;
      next.azimuth = az;
      next.point_of_ring.assign(static_cast<std::size_t>(beams), SIZE_MAX);
      columns.push_back(std::move(next));
      c = &columns.back();
    }
    c->point_of_ring[p.ring] = i;
    // A ring's elevation is one constant: a few dozen samples average the float rounding out.
    if (elevation_n[p.ring] < kElevationSamples) {
      elevation_sum[p.ring] += std::atan2(p.p.z(), std::hypot(p.p.x(), p.p.y()));
      elevation_n[p.ring] += 1;
    }
  }
  // Points that fall in columns of their own (a table that is not this head's) make a grid larger than the
  // per-point layout (9 bytes a point): then it is no grid.
  const std::size_t grid_bytes = columns.size() * (8 + 3 * static_cast<std::size_t>(beams));
  if (grid_bytes >= 9 * points.size()) return false;

  fillCommon(scan, m);
  m.layout = adit::lidar_scan_t::LAYOUT_GRID;
  m.range_scale = rangeScaleFor(points);
  m.intensity_scale = intensityScaleFor(points);
  m.azimuth_rate = static_cast<float>(rate);
  for (int r = 0; r < beams; ++r) {
    m.ring_elevation.push_back(elevation_n[r] ? static_cast<float>(elevation_sum[r] / elevation_n[r]) : 0.0f);
    m.ring_offset_ns.push_back(table.ring_offset_ns[r]);
  }
  m.num_columns = static_cast<std::int32_t>(columns.size());
  m.num_returns = m.num_columns * beams;
  m.range.assign(static_cast<std::size_t>(m.num_returns), 0);
  m.intensity.assign(static_cast<std::size_t>(m.num_returns), 0);
  for (std::size_t c = 0; c < columns.size(); ++c) {
    m.column_azimuth.push_back(columnAzimuthCount(columns[c].azimuth));
    m.column_time_ns.push_back(static_cast<std::int32_t>(std::lround(columns[c].time_ns)));
    for (int r = 0; r < beams; ++r) {
      const std::size_t i = columns[c].point_of_ring[r];
      if (i == SIZE_MAX) continue;
      const std::size_t k = c * static_cast<std::size_t>(beams) + static_cast<std::size_t>(r);
      // A return that rounds to 0 would read as no return: keep it at one count.
      m.range[k] = toU16(std::max(1L, std::lround(points[i].p.norm() / m.range_scale)));
      m.intensity[k] = intensityByte(points[i].intensity, m.intensity_scale);
    }
  }
  return true;
}

// Every point of the grid decodes back within tolerance, in the same order: else the layout is refused.
bool gridReproduces(const adit::lidar_scan_t& m, const std::vector<LidarPoint>& points) {
  LidarScan decoded;
  if (!decodeSweep(m, decoded).empty() || decoded.points.size() != points.size()) return false;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const LidarPoint& a = points[i];
    const LidarPoint& b = decoded.points[i];
    if (a.ring != b.ring || (a.p - b.p).norm() > sweepTolerance(a.p.norm(), m.range_scale) ||
        std::fabs(a.dt - b.dt) > 1e-6f)
      return false;
  }
  return true;
}

// ---- decoding ----

std::string checkCommon(const adit::lidar_scan_t& m) {
  if (m.format_version != kSweepFormatVersion)
    return "lidar_scan_t format_version " + std::to_string(m.format_version) + " is not one this build reads (" +
           std::to_string(kSweepFormatVersion) + ")";
  const int expected = profileBeams(m.sensor);
  if (m.num_beams < 0 || (expected > 0 && m.num_beams != expected))
    return "sensor '" + m.sensor + "' with " + std::to_string(m.num_beams) + " beams (profile: " +
           std::to_string(expected) + ")";
  if (!(m.range_scale > 0.0f && m.range_scale <= 0.05f)) return "range_scale " + std::to_string(m.range_scale);
  if (!(m.intensity_scale > 0.0f && std::isfinite(m.intensity_scale)))
    return "intensity_scale " + std::to_string(m.intensity_scale);
  if (!(m.sweep_duration >= 0.0f && m.sweep_duration <= 1.0f))
    return "sweep_duration " + std::to_string(m.sweep_duration) + " s";
  return "";
}

std::string decodeGrid(const adit::lidar_scan_t& m, LidarScan& s) {
  const int beams = m.num_beams;
  if (beams <= 0) return "a firing grid without beams";
  if (m.num_columns < 0 || static_cast<std::int64_t>(m.num_columns) * beams != m.num_returns)
    return std::to_string(m.num_returns) + " returns in " + std::to_string(m.num_columns) + " columns of " +
           std::to_string(beams);
  if (!std::isfinite(m.azimuth_rate) || std::fabs(m.azimuth_rate) > 2 * kTwoPi * 50)
    return "azimuth_rate " + std::to_string(m.azimuth_rate) + " rad/s";
  for (int r = 0; r < beams; ++r) {
    if (!(std::fabs(m.ring_elevation[r]) <= M_PI / 2)) return "elevation of ring " + std::to_string(r);
    if (m.ring_offset_ns[r] < 0 || m.ring_offset_ns[r] > 1'000'000)
      return "firing offset of ring " + std::to_string(r) + ": " + std::to_string(m.ring_offset_ns[r]) + " ns";
  }
  const double earliest_ns = -(static_cast<double>(m.sweep_duration) + 0.01) * 1e9;
  for (int c = 0; c < m.num_columns; ++c)
    if (m.column_time_ns[c] < earliest_ns || m.column_time_ns[c] > 1'000'000)
      return "column " + std::to_string(c) + " at " + std::to_string(m.column_time_ns[c]) + " ns, outside the sweep";
  std::vector<int> order(static_cast<std::size_t>(beams));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return m.ring_offset_ns[a] < m.ring_offset_ns[b]; });
  // Per ring: elevation and the azimuth the head turns between its column's time and its firing; per column
  // one cos/sin, each firing by angle addition (no trigonometry per point).
  std::vector<double> cos_el(beams), sin_el(beams), cos_turn(beams), sin_turn(beams);
  for (int r = 0; r < beams; ++r) {
    cos_el[r] = std::cos(static_cast<double>(m.ring_elevation[r]));
    sin_el[r] = std::sin(static_cast<double>(m.ring_elevation[r]));
    const double turn = m.azimuth_rate * (m.ring_offset_ns[r] * 1e-9);
    cos_turn[r] = std::cos(turn);
    sin_turn[r] = std::sin(turn);
  }
  s.points.reserve(static_cast<std::size_t>(m.num_returns));
  for (int c = 0; c < m.num_columns; ++c) {
    const double az0 = static_cast<double>(static_cast<std::uint32_t>(m.column_azimuth[c])) * kColumnAzimuthUnit;
    const double ca = std::cos(az0), sa = std::sin(az0);
    for (const int r : order) {
      const std::size_t k = static_cast<std::size_t>(c) * beams + static_cast<std::size_t>(r);
      if (m.range[k] == 0) continue;
      const double range = fromU16(m.range[k]) * m.range_scale;
      const double offset_s = m.ring_offset_ns[r] * 1e-9;
      const double cos_az = ca * cos_turn[r] - sa * sin_turn[r], sin_az = sa * cos_turn[r] + ca * sin_turn[r];
      const double h = range * cos_el[r];
      LidarPoint p;
      p.p = Eigen::Vector3f(static_cast<float>(h * cos_az), static_cast<float>(h * sin_az),
                            static_cast<float>(range * sin_el[r]));
      p.intensity = static_cast<float>(m.intensity[k]) * m.intensity_scale;
      p.ring = static_cast<std::uint16_t>(r);
      p.dt = static_cast<float>(m.column_time_ns[c] * 1e-9 + offset_s);
      s.points.push_back(p);
    }
  }
  return "";
}

std::string decodePoints(const adit::lidar_scan_t& m, LidarScan& s) {
  if (m.num_points != m.num_returns)
    return std::to_string(m.num_points) + " points for " + std::to_string(m.num_returns) + " returns";
  const double duration = m.sweep_duration;
  s.points.resize(static_cast<std::size_t>(m.num_points));
  for (int i = 0; i < m.num_points; ++i) {
    if (s.has_ring && s.num_beams > 0 && m.ring[i] >= s.num_beams)
      return "point " + std::to_string(i) + " on ring " + std::to_string(m.ring[i]) + " of " +
             std::to_string(s.num_beams);
    if (std::abs(m.elevation[i]) > 32767) return "point " + std::to_string(i) + " elevation out of range";
    LidarPoint& p = s.points[static_cast<std::size_t>(i)];
    const double range = fromU16(m.range[i]) * m.range_scale;
    const CosSin& az = azimuthCosSin(m.azimuth[i]);
    const CosSin& el = elevationCosSin(m.elevation[i]);
    const double h = range * el.cos;
    p.p = {static_cast<float>(h * az.cos), static_cast<float>(h * az.sin), static_cast<float>(range * el.sin)};
    p.intensity = static_cast<float>(m.intensity[i]) * m.intensity_scale;
    p.ring = m.ring[i];
    p.dt = static_cast<float>(-fromU16(m.time[i]) / 65535.0 * duration);
  }
  return "";
}

}  // namespace

int profileBeams(const std::string& sensor) {
  if (sensor == "vlp16" || sensor == "rs16") return 16;
  if (sensor == "vlp32c" || sensor == "hdl32e") return 32;
  if (sensor == "hdl64") return 64;
  return 0;
}

double sweepTolerance(double range_m, float range_scale) { return 0.5 * range_scale + 1e-4 * range_m + 1e-5; }

adit::lidar_scan_t encodeSweep(const LidarScan& scan, const FiringTable* table) {
  const std::vector<LidarPoint> points = finitePoints(scan);
  adit::lidar_scan_t grid;
  if (table && encodeGrid(scan, points, *table, grid) && gridReproduces(grid, points)) return grid;
  return encodePoints(scan, points);
}

std::string decodeSweep(const adit::lidar_scan_t& m, LidarScan& scan) {
  if (std::string e = checkCommon(m); !e.empty()) return e;
  scan = sweepHeader(m);
  if (m.layout == adit::lidar_scan_t::LAYOUT_GRID) return decodeGrid(m, scan);
  if (m.layout == adit::lidar_scan_t::LAYOUT_POINTS) return decodePoints(m, scan);
  return "unknown layout " + std::to_string(m.layout);
}

int SweepMessage::decode(const void* buf, int offset, int maxlen) {
  const auto* bytes = static_cast<const std::uint8_t*>(buf) + offset;
  if (maxlen < 8) return -1;
  std::uint64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | bytes[i];
  error.clear();
  unknown_version = false;
  if (static_cast<std::int64_t>(hash) == adit::lidar_scan_t::getHash()) {
    adit::lidar_scan_t m;
    const int used = m.decode(buf, offset, maxlen);
    if (used < 0) return used;
    header = m.header;
    compact = true;
    unknown_version = m.format_version != kSweepFormatVersion;
    error = decodeSweep(m, scan);
    return used;
  }
  adit::point_cloud_t m;
  const int used = m.decode(buf, offset, maxlen);
  if (used < 0) return used;
  header = m.header;
  compact = false;
  scan = fromMessage(m);
  return used;
}

Validation validate(const SweepMessage& m, const InputLimits& limits) {
  if (Validation v = validate(m.header, limits)) return v;
  const double duration = m.scan.sweep_duration;
  if (!std::isfinite(duration) || duration < 0 || duration > limits.max_sweep_duration)
    return Invalid{"invalid_range", "sweep_duration " + std::to_string(duration) + " s is not a sweep's"};
  return std::nullopt;
}

}  // namespace adit::msg
