#include "io/pcd.hpp"

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "io/atomic_file.hpp"
#include "io/rings.hpp"

namespace adit::io {
namespace fs = std::filesystem;
namespace {

constexpr double kAbsoluteTimeThreshold = 1e6;  // s; per-point times above this are absolute (epoch)

// One scalar field of a PCLPointCloud2, read as double whatever its stored type.
struct FieldReader {
  bool present = false;
  std::uint32_t offset = 0;
  std::uint8_t datatype = 0;

  bool isInteger() const {
    return datatype != pcl::PCLPointField::FLOAT32 && datatype != pcl::PCLPointField::FLOAT64;
  }

  template <class T>
  static double load(const std::uint8_t* p) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return static_cast<double>(v);
  }

  double read(const std::uint8_t* point) const {
    const std::uint8_t* p = point + offset;
    switch (datatype) {
      case pcl::PCLPointField::INT8: return load<std::int8_t>(p);
      case pcl::PCLPointField::UINT8: return load<std::uint8_t>(p);
      case pcl::PCLPointField::INT16: return load<std::int16_t>(p);
      case pcl::PCLPointField::UINT16: return load<std::uint16_t>(p);
      case pcl::PCLPointField::INT32: return load<std::int32_t>(p);
      case pcl::PCLPointField::UINT32: return load<std::uint32_t>(p);
      case pcl::PCLPointField::INT64: return load<std::int64_t>(p);
      case pcl::PCLPointField::UINT64: return load<std::uint64_t>(p);
      case pcl::PCLPointField::FLOAT32: return load<float>(p);
      case pcl::PCLPointField::FLOAT64: return load<double>(p);
      default: return std::numeric_limits<double>::quiet_NaN();
    }
  }
};

FieldReader findField(const pcl::PCLPointCloud2& cloud, const std::string& name) {
  FieldReader f;
  for (const auto& field : cloud.fields) {
    if (field.name != name || field.count < 1) continue;
    f.present = true;
    f.offset = field.offset;
    f.datatype = field.datatype;
    break;
  }
  return f;
}

std::uint32_t bytesOf(std::uint8_t datatype) {
  switch (datatype) {
    case pcl::PCLPointField::INT8:
    case pcl::PCLPointField::UINT8: return 1;
    case pcl::PCLPointField::INT16:
    case pcl::PCLPointField::UINT16: return 2;
    case pcl::PCLPointField::INT32:
    case pcl::PCLPointField::UINT32:
    case pcl::PCLPointField::FLOAT32: return 4;
    case pcl::PCLPointField::INT64:
    case pcl::PCLPointField::UINT64:
    case pcl::PCLPointField::FLOAT64: return 8;
    default: return 0;
  }
}

// PCL's reader trusts the header (a garbage file can crash it), so the header and the body size are
// checked here first. Returns an empty string if the file is safe to hand to PCL, else the problem.
std::string checkPcdFile(const std::string& path) {
  pcl::PCLPointCloud2 header;
  Eigen::Vector4f origin;
  Eigen::Quaternionf orientation;
  int version = 0, data_type = 0;
  unsigned int data_idx = 0;
  pcl::PCDReader reader;
  if (reader.readHeader(path, header, origin, orientation, version, data_type, data_idx) < 0) return "no valid PCD header";
  if (header.fields.empty()) return "header lists no fields";
  std::uint64_t point_bytes = 0;
  for (const auto& f : header.fields) {
    if (bytesOf(f.datatype) == 0 || f.count < 1) return "field '" + f.name + "' has an unknown type or count";
    point_bytes += static_cast<std::uint64_t>(bytesOf(f.datatype)) * f.count;
  }
  const std::uint64_t body = point_bytes * header.width * header.height;
  const std::uint64_t file_bytes = fs::file_size(path);
  std::uint64_t values_per_point = 0;
  for (const auto& f : header.fields) values_per_point += f.count;
  // ascii: every value takes at least a digit and a separator; catches a huge WIDTH before PCL allocates.
  if (data_type == 0 && file_bytes < data_idx + 2 * values_per_point * header.width * header.height)
    return "truncated: too few bytes for the announced " + std::to_string(header.width * header.height) + " points";
  if (data_type == 1 && file_bytes < data_idx + body)  // binary: raw body follows the header
    return "truncated: " + std::to_string(file_bytes) + " bytes, header announces " + std::to_string(data_idx + body);
  if (data_type == 2 && body > 0) {  // binary_compressed: uint32 compressed size, uint32 raw size, LZF data
    std::ifstream in(path, std::ios::binary);
    std::uint32_t sizes[2] = {0, 0};
    in.seekg(data_idx);
    if (!in.read(reinterpret_cast<char*>(sizes), sizeof(sizes))) return "truncated before the compressed body";
    if (sizes[1] != body) return "compressed body size does not match the header";
    if (file_bytes < data_idx + 8ull + sizes[0]) return "truncated compressed body";
  }
  return "";
}

pcl::PCLPointCloud2 loadCloud(const std::string& path) {
  if (!fs::is_regular_file(path)) throw ReadError("PCD: file '" + path + "' does not exist");
  pcl::PCLPointCloud2 cloud;
  int status = -1;
  try {
    const std::string problem = checkPcdFile(path);
    if (!problem.empty()) throw ReadError("PCD: '" + path + "' is corrupt: " + problem);
    pcl::PCDReader reader;
    status = reader.read(path, cloud);
  } catch (const ReadError&) {
    throw;
  } catch (const std::exception& e) {
    throw ReadError("PCD: cannot parse '" + path + "': " + e.what());
  }
  if (status < 0) throw ReadError("PCD: cannot parse '" + path + "' (corrupt or truncated, PCL status " + std::to_string(status) + ")");
  const std::size_t n = static_cast<std::size_t>(cloud.width) * cloud.height;
  if (cloud.data.size() < n * cloud.point_step)
    throw ReadError("PCD: '" + path + "' holds fewer bytes than its header announces");
  return cloud;
}

// Per-point times to dt (<= 0, last firing at 0). Returns the span (s) and the largest time (s).
struct TimeFill {
  bool usable = false;
  bool absolute = false;
  double max_seconds = 0.0;
  double span_seconds = 0.0;
};

TimeFill fillTimes(const pcl::PCLPointCloud2& cloud, const FieldReader& time, std::vector<LidarPoint>& points) {
  TimeFill fill;
  const double scale = time.isInteger() ? 1e-9 : 1.0;
  std::vector<double> seconds(points.size(), std::numeric_limits<double>::quiet_NaN());
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double s = time.read(cloud.data.data() + i * cloud.point_step) * scale;
    if (!std::isfinite(s)) continue;
    seconds[i] = s;
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  if (!(hi > lo)) return fill;  // no finite times, or all equal: no timing information
  fill.absolute = hi > kAbsoluteTimeThreshold;
  // float32 epoch seconds keep only ~2 min resolution: useless for per-point timing.
  if (fill.absolute && time.datatype == pcl::PCLPointField::FLOAT32) return fill;
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
  return end != stem.c_str() && *end == '\0' && std::isfinite(seconds) && seconds >= 0.0;
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
  const long long ns = std::stoll(stem);
  if (ns <= 1000000000000LL) return false;  // small integers are frame numbers, not nanoseconds
  utime = (ns + 500) / 1000;
  return true;
}

LidarScan readPcdScan(const std::string& path, const PcdFolderConfig& config, std::int64_t utime, std::int64_t seq,
                      PcdScanReport* report) {
  const pcl::PCLPointCloud2 cloud = loadCloud(path);
  const FieldReader x = findField(cloud, "x"), y = findField(cloud, "y"), z = findField(cloud, "z");
  if (!x.present || !y.present || !z.present) throw ReadError("PCD: '" + path + "' has no x, y and z fields");
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
  scan.points.resize(static_cast<std::size_t>(cloud.width) * cloud.height);
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
    scan.has_ring = true;
    scan.num_beams = config.num_beams > 0 ? config.num_beams : max_ring + 1;
  } else {
    scan.has_ring = assignRingsWithoutField(config, scan, local);
  }

  TimeFill times;
  if (time.present) times = fillTimes(cloud, time, scan.points);
  scan.has_time = times.usable;
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
  pcl::PCLPointCloud2 cloud;
  std::uint32_t offset = 0;
  auto addField = [&](const char* name, std::uint8_t datatype, std::uint32_t bytes) {
    pcl::PCLPointField f;
    f.name = name;
    f.offset = offset;
    f.datatype = datatype;
    f.count = 1;
    cloud.fields.push_back(f);
    offset += bytes;
  };
  for (const char* name : {"x", "y", "z", "intensity"}) addField(name, pcl::PCLPointField::FLOAT32, 4);
  if (options.with_ring) addField("ring", pcl::PCLPointField::UINT16, 2);
  if (options.with_time) addField("time", pcl::PCLPointField::FLOAT32, 4);
  cloud.point_step = offset;
  cloud.width = static_cast<std::uint32_t>(points.size());
  cloud.height = 1;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_dense = std::all_of(points.begin(), points.end(), [](const LidarPoint& p) { return p.p.allFinite(); });
  cloud.data.resize(static_cast<std::size_t>(cloud.row_step));
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::uint8_t* out = cloud.data.data() + i * cloud.point_step;
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
  pcl::PCDWriter writer;
  const std::string header =
      writer.generateHeaderBinary(cloud, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity());
  writeFileAtomically(path, [&](std::ostream& out) {
    out << header << "DATA binary\n";
    out.write(reinterpret_cast<const char*>(cloud.data.data()), static_cast<std::streamsize>(cloud.data.size()));
  });
}

}  // namespace adit::io
