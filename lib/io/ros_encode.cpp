#include "io/ros_encode.hpp"

#include <cstring>

namespace adit::io {
namespace {

template <typename T>
void put(RosBytes& b, T v) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
  b.insert(b.end(), p, p + sizeof(T));
}
void putString(RosBytes& b, const std::string& s) {
  put<std::uint32_t>(b, static_cast<std::uint32_t>(s.size()));
  b.insert(b.end(), s.begin(), s.end());
}
void putHeader(RosBytes& b, const RosHeader& h) {
  put(b, h.seq);
  put(b, h.stamp.sec);
  put(b, h.stamp.nsec);
  putString(b, h.frame_id);
}
void putVector3(RosBytes& b, const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) put(b, v[i]);
}
void putCovariance(RosBytes& b, double first) {
  put(b, first);
  for (int i = 1; i < 9; ++i) put(b, 0.0);  // all zero: "unknown", as most drivers leave it
}

template <typename T>
void store(std::uint8_t* at, T v) {
  std::memcpy(at, &v, sizeof(T));
}

const char kSeparator[] = "================================================================================\n";
const std::string kHeaderDefinition = std::string(kSeparator) + "MSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id\n";

}  // namespace

RosStamp rosStampOf(std::int64_t utime) {
  return {static_cast<std::uint32_t>(utime / 1000000), static_cast<std::uint32_t>(utime % 1000000) * 1000u};
}

RosBytes encodePointCloud2(const RosHeader& header, const std::vector<RosPointField>& fields, std::uint32_t point_step,
                           const std::vector<std::uint8_t>& points, std::uint32_t height, std::uint32_t row_padding) {
  RosBytes b;
  b.reserve(points.size() + 256);
  putHeader(b, header);
  const auto per_row = static_cast<std::uint32_t>(point_step == 0 || height == 0 ? 0 : points.size() / point_step / height);
  put(b, height);
  put(b, per_row);
  put<std::uint32_t>(b, static_cast<std::uint32_t>(fields.size()));
  for (const RosPointField& f : fields) {
    putString(b, f.name);
    put(b, f.offset);
    put(b, f.datatype);
    put<std::uint32_t>(b, 1);  // count
  }
  put<std::uint8_t>(b, 0);  // is_bigendian
  put(b, point_step);
  const std::uint32_t row_step = per_row * point_step + row_padding;
  put(b, row_step);
  put<std::uint32_t>(b, row_step * height);
  for (std::uint32_t r = 0; r < height; ++r) {
    const auto* row = points.data() + std::size_t{r} * per_row * point_step;
    b.insert(b.end(), row, row + std::size_t{per_row} * point_step);
    b.insert(b.end(), row_padding, 0xAB);
  }
  put<std::uint8_t>(b, 1);  // is_dense
  return b;
}

RosBytes encodeVelodyneCloud(const LidarScan& scan, std::uint32_t seq, const std::string& frame_id) {
  constexpr std::uint32_t kStep = 32;
  std::vector<std::uint8_t> data(scan.points.size() * kStep, 0);
  std::uint8_t* at = data.data();
  for (const LidarPoint& p : scan.points) {
    store(at, p.p.x());
    store(at + 4, p.p.y());
    store(at + 8, p.p.z());
    store(at + 16, p.intensity);
    store(at + 20, p.ring);
    store(at + 24, p.dt);
    at += kStep;
  }
  return encodePointCloud2({seq, rosStampOf(scan.utime), frame_id},
                           {{"x", 0, 7}, {"y", 4, 7}, {"z", 8, 7}, {"intensity", 16, 7}, {"ring", 20, 4}, {"time", 24, 7}},
                           kStep, data);
}

RosBytes encodeImu(const RosHeader& header, const ImuSample& s) {
  RosBytes b;
  b.reserve(400);
  putHeader(b, header);
  const Eigen::Quaterniond q = s.orientation.value_or(Eigen::Quaterniond(0, 0, 0, 0));
  for (const double v : {q.x(), q.y(), q.z(), q.w()}) put(b, v);
  putCovariance(b, s.orientation ? 0.0 : -1.0);
  putVector3(b, s.gyro);
  putCovariance(b, 0.0);
  putVector3(b, s.accel);
  putCovariance(b, 0.0);
  return b;
}

const RosMessageType& pointCloud2Type() {
  static const RosMessageType type{
      "sensor_msgs/PointCloud2", "1158d486dd51d683ce2f1be655c3c181",
      "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\nbool is_bigendian\n"
      "uint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n\n" +
          kHeaderDefinition + "\n" + kSeparator +
          "MSG: sensor_msgs/PointField\nuint8 INT8    = 1\nuint8 UINT8   = 2\nuint8 INT16   = 3\nuint8 UINT16  = 4\n"
          "uint8 INT32   = 5\nuint8 UINT32  = 6\nuint8 FLOAT32 = 7\nuint8 FLOAT64 = 8\nstring name\nuint32 offset\n"
          "uint8 datatype\nuint32 count\n"};
  return type;
}

const RosMessageType& imuType() {
  static const RosMessageType type{
      "sensor_msgs/Imu", "6a62c6daae103f4ff57a132d6f95cec2",
      "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n"
      "geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n"
      "geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n\n" +
          kHeaderDefinition + "\n" + kSeparator + "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n\n" +
          kSeparator + "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"};
  return type;
}

}  // namespace adit::io
