#include "io/pcd.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>

#include "io/atomic_file.hpp"
#include "io/limits.hpp"
#include "io/pcd_format.hpp"
#include "io/rings.hpp"

namespace adit::io {
namespace fs = std::filesystem;
namespace {

constexpr double kAbsoluteTimeThreshold = 1e6;  // s; per-point times above this are absolute (epoch)

// One scalar field, read as double whatever its stored type; absent fields read nothing.
struct FieldReader {
  bool present = false;
  PcdField field;
  bool isInteger() const { return field.isInteger(); }
  bool isFloat32() const { return field.type == 'F' && field.size == 4; }
  double read(const std::uint8_t* point) const { return field.read(point); }
};

FieldReader findField(const PcdCloud& cloud, const std::string& name) {
  FieldReader f;
  if (const PcdField* field = cloud.field(name)) {
    f.present = true;
    f.field = *field;
  }
  return f;
}

// Per-point times to dt (<= 0, last firing at 0). Returns the span (s) and the largest time (s).
struct TimeFill {
  bool usable = false;
  bool absolute = false;
  double max_seconds = 0.0;
  double span_seconds = 0.0;
};

TimeFill fillTimes(const PcdCloud& cloud, const FieldReader& time, std::vector<LidarPoint>& points) {
  TimeFill fill;
  const double scale = time.isInteger() ? 1e-9 : 1.0;
  std::vector<double> seconds(points.size(), std::numeric_limits<double>::quiet_NaN());
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double s = time.read(cloud.data.data() + i * cloud.point_step) * scale;
    if (!std::isfinite(s) || std::fabs(s) > kMaxStampSeconds) continue;  // absurd: as if absent
    seconds[i] = s;
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  if (!(hi > lo)) return fill;  // no finite times, or all equal: no timing information
  fill.absolute = hi > kAbsoluteTimeThreshold;
  // float32 epoch seconds keep only ~2 min resolution: useless for per-point timing.
  if (fill.absolute && time.isFloat32()) return fill;
  fill.usable = true;
  fill.max_seconds = hi;
  fill.span_seconds = hi - lo;
  for (std::size_t i = 0; i < points.size(); ++i)
    points[i].dt = std::isfinite(seconds[i]) ? static_cast<float>(seconds[i] - hi) : 0.0f;
  return fill;
}

// Rings from the sensor's beam table or a uniform fan; false if neither is known.
bool assignRingsWithoutField(const PcdFolderConfig& config, LidarScan& scan, PcdScanReport& report) {
  std::vector<double> table = beamTable(config.sensor);
  if (table.empty() && config.num_beams > 0)
    table = uniformElevations(config.num_beams, config.min_elevation_deg * M_PI / 180.0,
                              config.max_elevation_deg * M_PI / 180.0);
  if (table.empty()) return false;
  const RingAssignmentStats stats = assignRingsByElevation(scan.points, table, M_PI / 180.0);
  report.far_from_beam = stats.far_from_beam;
  scan.num_beams = static_cast<int>(table.size());
  return true;
}

bool parseDecimalSeconds(const std::string& stem, double& seconds) {
  if (stem.find('.') == std::string::npos) return false;
  char* end = nullptr;
  seconds = std::strtod(stem.c_str(), &end);
  return end != stem.c_str() && *end == '\0' && std::isfinite(seconds) && seconds >= 0.0 && seconds <= kMaxStampSeconds;
}

}  // namespace

PcdFolderConfig pcdFolderConfigFrom(const Config& c) {
  PcdFolderConfig d;
  d.sensor = c.get<std::string>("pcd.sensor", d.sensor);
  d.num_beams = c.get<int>("pcd.num_beams", d.num_beams);
  d.min_elevation_deg = c.get<double>("pcd.min_elevation_deg", d.min_elevation_deg);
  d.max_elevation_deg = c.get<double>("pcd.max_elevation_deg", d.max_elevation_deg);
  d.sweep_duration = c.get<double>("pcd.sweep_duration", d.sweep_duration);
  d.first_utime = c.get<std::int64_t>("pcd.first_utime", d.first_utime);
  d.stamp_is_sweep_start = c.get<bool>("pcd.stamp_is_sweep_start", d.stamp_is_sweep_start);
  return d;
}

bool pcdStampFromFileName(const std::string& path, std::int64_t& utime) {
  const std::string stem = fs::path(path).stem().string();
  double seconds = 0.0;
  if (parseDecimalSeconds(stem, seconds)) {
    utime = toUtime(seconds);
    return true;
  }
  const bool digits = !stem.empty() && stem.size() <= 19 &&
                      std::all_of(stem.begin(), stem.end(), [](char c) { return c >= '0' && c <= '9'; });
  if (!digits) return false;
  errno = 0;
  const long long ns = std::strtoll(stem.c_str(), nullptr, 10);
  if (errno == ERANGE) return false;  // 19 digits above INT64_MAX
  if (ns <= 1000000000000LL) return false;  // small integers are frame numbers, not nanoseconds
  utime = (ns + 500) / 1000;
  return true;
}

LidarScan readPcdScan(const std::string& path, const PcdFolderConfig& config, std::int64_t utime, std::int64_t seq,
                      PcdScanReport* report) {
  return scanFromCloud(readPcdFile(path), config, utime, seq, "PCD: '" + path + "'", report);
}

LidarScan scanFromCloud(const PcdCloud& cloud, const PcdFolderConfig& config, std::int64_t utime, std::int64_t seq,
                        const std::string& name, PcdScanReport* report) {
  const FieldReader x = findField(cloud, "x"), y = findField(cloud, "y"), z = findField(cloud, "z");
  if (!x.present || !y.present || !z.present) throw ReadError(name + " has no x, y and z fields");
  const FieldReader intensity = findField(cloud, "intensity");
  const FieldReader ring = findField(cloud, "ring");
  PcdScanReport local;
  FieldReader time;
  for (const char* name : {"time", "t", "timestamp"}) {
    time = findField(cloud, name);
    if (time.present) {
      local.time_field = name;
      break;
    }
  }

  LidarScan scan;
  scan.utime = utime;
  scan.seq = seq;
  scan.sensor = config.sensor;
  scan.sweep_duration = static_cast<float>(config.sweep_duration);
  scan.points.resize(cloud.points);
  int max_ring = -1;
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    const std::uint8_t* raw = cloud.data.data() + i * cloud.point_step;
    LidarPoint& pt = scan.points[i];
    pt.p = Eigen::Vector3f(static_cast<float>(x.read(raw)), static_cast<float>(y.read(raw)), static_cast<float>(z.read(raw)));
    if (!pt.p.allFinite()) ++local.nan_points;
    if (intensity.present) pt.intensity = static_cast<float>(intensity.read(raw));
    if (ring.present) {
      const double r = ring.read(raw);
      pt.ring = (std::isfinite(r) && r >= 0.0 && r < 65536.0) ? static_cast<std::uint16_t>(r) : 0;
      max_ring = std::max(max_ring, static_cast<int>(pt.ring));
    }
  }

  if (ring.present) {
    local.ring_field = true;
    local.rings_flipped = orientRingsBottomUp(scan.points);
    scan.has_ring = true;
    scan.num_beams = config.num_beams > 0 ? config.num_beams : max_ring + 1;
  } else {
    scan.has_ring = assignRingsWithoutField(config, scan, local);
  }

  TimeFill times;
  if (time.present) times = fillTimes(cloud, time, scan.points);
  scan.has_time = times.usable;
  local.time_max_seconds = times.max_seconds;
  if (times.usable && times.absolute) {
    scan.utime = toUtime(times.max_seconds);
    local.absolute_times = true;
  }
  if (report) *report = local;
  return scan;
}

PcdFolder::PcdFolder(const std::string& folder, const PcdFolderConfig& config) : config_(config) {
  if (!fs::is_directory(folder)) throw ReadError("PCD: folder '" + folder + "' does not exist");
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.path().extension() == ".pcd") files_.push_back(entry.path().string());
  std::sort(files_.begin(), files_.end());
  names_are_timestamps_ = !files_.empty();
  for (const std::string& file : files_) {
    std::int64_t stamp = 0;
    if (!pcdStampFromFileName(file, stamp)) {
      names_are_timestamps_ = false;
      stamps_.clear();
      break;
    }
    stamps_.push_back(stamp);
  }
}

std::int64_t PcdFolder::nominalUtime(std::size_t i) const {
  if (names_are_timestamps_) return stamps_.at(i);
  return config_.first_utime + toUtime(config_.sweep_duration * static_cast<double>(i));
}

LidarScan PcdFolder::scan(std::size_t i, PcdScanReport* report) const {
  if (i >= size()) throw ReadError("PCD: scan index " + std::to_string(i) + " out of range (" + std::to_string(size()) + " files)");
  PcdScanReport local;
  LidarScan scan = readPcdScan(files_[i], config_, nominalUtime(i), static_cast<std::int64_t>(i), &local);
  if (names_are_timestamps_ && config_.stamp_is_sweep_start && !local.absolute_times) {
    double span = config_.sweep_duration;
    if (scan.has_time) {
      span = 0.0;
      for (const LidarPoint& pt : scan.points) span = std::max(span, -static_cast<double>(pt.dt));
    }
    scan.utime += toUtime(span);
  }
  if (report) *report = local;
  return scan;
}

void writePcd(const std::string& path, const std::vector<LidarPoint>& points, const PcdWriteOptions& options) {
  std::vector<PcdField> fields;
  std::size_t step = 0;
  auto addField = [&](const char* name, char type, std::uint32_t bytes) {
    PcdField f;
    f.name = name;
    f.type = type;
    f.size = bytes;
    f.offset = step;
    fields.push_back(f);
    step += bytes;
  };
  for (const char* name : {"x", "y", "z", "intensity"}) addField(name, 'F', 4);
  if (options.with_ring) addField("ring", 'U', 2);
  if (options.with_time) addField("time", 'F', 4);
  std::vector<std::uint8_t> data(points.size() * step);
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::uint8_t* out = data.data() + i * step;
    const LidarPoint& pt = points[i];
    const float xyzi[4] = {pt.p.x(), pt.p.y(), pt.p.z(), pt.intensity};
    std::memcpy(out, xyzi, sizeof(xyzi));
    std::size_t at = sizeof(xyzi);
    if (options.with_ring) {
      std::memcpy(out + at, &pt.ring, sizeof(pt.ring));
      at += sizeof(pt.ring);
    }
    if (options.with_time) std::memcpy(out + at, &pt.dt, sizeof(pt.dt));
  }
  const std::string header = pcdBinaryHeader(fields, points.size());
  writeFileAtomically(path, [&](std::ostream& out) {
    out << header;
    out.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size()));
  });
}

}  // namespace adit::io
