#include "io/ros_messages.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "io/pcd_format.hpp"

namespace adit::io {
namespace {

// Reads ROS 1 serialised fields front to back; running past the end throws DecodeError.
class RosReader {
 public:
  RosReader(const std::uint8_t* data, std::size_t size, const char* what) : data_(data), size_(size), what_(what) {}
  template <typename T>
  T get() {
    need(sizeof(T));
    T v;
    std::memcpy(&v, data_ + at_, sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  std::string string() {
    const std::uint32_t n = get<std::uint32_t>();
    need(n);
    std::string s(reinterpret_cast<const char*>(data_ + at_), n);
    at_ += n;
    return s;
  }
  // A uint8[] array: its bytes stay in the message (no copy).
  const std::uint8_t* bytes(std::uint32_t& n) {
    n = get<std::uint32_t>();
    need(n);
    const std::uint8_t* p = data_ + at_;
    at_ += n;
    return p;
  }
  RosStamp header(std::int64_t& utime, std::int64_t fallback) {
    get<std::uint32_t>();  // seq
    RosStamp stamp{get<std::uint32_t>(), get<std::uint32_t>()};
    string();  // frame_id
    if (stamp.nsec >= 1000000000u) throw DecodeError(std::string(what_) + ": header stamp nsecs out of range");
    utime = stamp.sec == 0 && stamp.nsec == 0 ? fallback : stamp.utime();
    return stamp;
  }
  Eigen::Vector3d vector3() {
    const double x = get<double>(), y = get<double>(), z = get<double>();
    return {x, y, z};
  }
  void skip(std::size_t n) {
    need(n);
    at_ += n;
  }

 private:
  void need(std::size_t n) const {
    if (n > size_ - at_) throw DecodeError(std::string(what_) + ": message ends early (" + std::to_string(size_) + " bytes)");
  }
  const std::uint8_t* data_;
  std::size_t size_, at_ = 0;
  const char* what_;
};

// sensor_msgs/PointField datatypes 1..8 (INT8 UINT8 INT16 UINT16 INT32 UINT32 FLOAT32 FLOAT64) as PCD types.
bool pcdType(std::uint8_t datatype, PcdField& f) {
  static const char kType[] = {'I', 'U', 'I', 'U', 'I', 'U', 'F', 'F'};
  static const std::uint32_t kSize[] = {1, 1, 2, 2, 4, 4, 4, 8};
  if (datatype < 1 || datatype > 8) return false;
  f.type = kType[datatype - 1];
  f.size = kSize[datatype - 1];
  return true;
}

// Converts every field of a big-endian cloud to little-endian in place.
void swapToLittleEndian(PcdCloud& cloud) {
  for (std::size_t i = 0; i < cloud.points; ++i)
    for (const PcdField& f : cloud.fields) {
      std::uint8_t* p = cloud.data.data() + i * cloud.point_step + f.offset;
      for (std::uint32_t e = 0; e < f.count; ++e, p += f.size) std::reverse(p, p + f.size);
    }
}

}  // namespace

LidarScan decodePointCloud2(const std::uint8_t* data, std::size_t size, const PcdFolderConfig& config,
                            std::int64_t fallback_utime, PcdScanReport* report) {
  const char* what = "PointCloud2";
  RosReader in(data, size, what);
  std::int64_t stamp = 0;
  in.header(stamp, fallback_utime);
  const std::uint32_t height = in.get<std::uint32_t>(), width = in.get<std::uint32_t>();
  const std::uint32_t num_fields = in.get<std::uint32_t>();
  PcdCloud cloud;
  for (std::uint32_t k = 0; k < num_fields; ++k) {
    PcdField f;
    f.name = in.string();
    f.offset = in.get<std::uint32_t>();
    const std::uint8_t datatype = in.get<std::uint8_t>();
    f.count = std::max<std::uint32_t>(1, in.get<std::uint32_t>());
    if (!pcdType(datatype, f)) throw DecodeError(std::string(what) + ": field '" + f.name + "' has unknown datatype " + std::to_string(datatype));
    cloud.fields.push_back(f);
  }
  const bool big_endian = in.get<std::uint8_t>() != 0;
  const std::uint32_t point_step = in.get<std::uint32_t>(), row_step = in.get<std::uint32_t>();
  std::uint32_t data_size = 0;
  const std::uint8_t* points = in.bytes(data_size);
  for (const PcdField& f : cloud.fields)
    if (f.offset > point_step || std::uint64_t{f.size} * f.count > point_step - f.offset)
      throw DecodeError(std::string(what) + ": field '" + f.name + "' lies outside point_step " + std::to_string(point_step));
  const std::uint64_t row_bytes = std::uint64_t{width} * point_step;
  // Each product is below 2^64 (32-bit factors); compared separately so that no sum can wrap.
  const bool fits = height == 0 || (row_bytes <= data_size && std::uint64_t{row_step} * (height - 1) <= data_size - row_bytes);
  if (point_step == 0 || row_step < row_bytes || !fits)
    throw DecodeError(std::string(what) + ": " + std::to_string(height) + " x " + std::to_string(width) + " points of " +
                      std::to_string(point_step) + " bytes (row_step " + std::to_string(row_step) + ") do not fit its " +
                      std::to_string(data_size) + " data bytes");
  cloud.point_step = point_step;
  cloud.points = std::size_t{height} * width;
  cloud.data.resize(cloud.points * point_step);  // bounded by data_size, checked above
  // Repack: rows may be padded. An empty row (width 0) copies nothing, however many rows are declared.
  for (std::uint32_t r = 0; row_bytes > 0 && r < height; ++r)
    std::memcpy(cloud.data.data() + r * row_bytes, points + std::uint64_t{r} * row_step, row_bytes);
  if (big_endian) swapToLittleEndian(cloud);

  PcdScanReport local;
  LidarScan scan = scanFromCloud(cloud, config, stamp, 0, what, &local);
  if (scan.has_time && !local.absolute_times) scan.utime = stamp + toUtime(local.time_max_seconds);
  if (report) *report = local;
  return scan;
}

ImuSample decodeImu(const std::uint8_t* data, std::size_t size, std::int64_t fallback_utime) {
  RosReader in(data, size, "Imu");
  ImuSample s;
  in.header(s.utime, fallback_utime);
  const double qx = in.get<double>(), qy = in.get<double>(), qz = in.get<double>(), qw = in.get<double>();
  const double orientation_cov0 = in.get<double>();
  in.skip(8 * 8);
  s.gyro = in.vector3();
  in.skip(9 * 8);
  s.accel = in.vector3();
  in.skip(9 * 8);
  if (!s.gyro.allFinite() || !s.accel.allFinite()) throw DecodeError("Imu: non-finite angular velocity or acceleration");
  // Covariance[0] = -1 is the message's own "no orientation" mark; an all-zero quaternion means the same in practice.
  const Eigen::Quaterniond q(qw, qx, qy, qz);
  if (orientation_cov0 != -1.0 && std::isfinite(q.norm()) && std::fabs(q.norm() - 1.0) < 1e-3) s.orientation = q.normalized();
  return s;
}

}  // namespace adit::io
