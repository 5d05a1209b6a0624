#include "drivers/fdilink.hpp"

#include <cmath>
#include <cstring>

namespace adit::drivers {
namespace {

constexpr std::uint8_t kStart = 0xFC;
constexpr std::uint8_t kEnd = 0xFD;
constexpr std::size_t kHeaderBytes = 7;       // start, type, length, serial, CRC8, CRC16 hi, lo
constexpr std::size_t kMaxBuffered = 4096;    // more than any frame (255 + 8): older bytes are noise

float readFloat(const std::uint8_t* p) {
  std::uint32_t u = 0;
  for (int i = 3; i >= 0; --i) u = (u << 8) | p[i];
  float f;
  std::memcpy(&f, &u, sizeof f);
  return f;
}

std::int64_t readInt64(const std::uint8_t* p) {
  std::uint64_t u = 0;
  for (int i = 7; i >= 0; --i) u = (u << 8) | p[i];
  return static_cast<std::int64_t>(u);
}

void writeFloat(std::vector<std::uint8_t>& out, float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(u >> (8 * i)));
}

void writeInt64(std::vector<std::uint8_t>& out, std::int64_t v) {
  const auto u = static_cast<std::uint64_t>(v);
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<std::uint8_t>(u >> (8 * i)));
}

// Reads `count` float32 fields from `p`; false if one is not finite.
bool readFloats(const std::uint8_t* p, int count, double* out) {
  for (int i = 0; i < count; ++i) {
    out[i] = readFloat(p + 4 * i);
    if (!std::isfinite(out[i])) return false;
  }
  return true;
}

}  // namespace

std::uint8_t fdiCrc8(const std::uint8_t* data, std::size_t size) {
  std::uint8_t crc = 0;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= data[i];
    for (int bit = 0; bit < 8; ++bit) crc = (crc & 1) ? static_cast<std::uint8_t>((crc >> 1) ^ 0x8C) : crc >> 1;
  }
  return crc;
}

std::uint16_t fdiCrc16(const std::uint8_t* data, std::size_t size) {
  std::uint16_t crc = 0;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= static_cast<std::uint16_t>(data[i] << 8);
    for (int bit = 0; bit < 8; ++bit)
      crc = (crc & 0x8000) ? static_cast<std::uint16_t>((crc << 1) ^ 0x1021) : static_cast<std::uint16_t>(crc << 1);
  }
  return crc;
}

std::vector<std::uint8_t> encodeFdiFrame(std::uint8_t type, std::uint8_t serial, const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> f{kStart, type, static_cast<std::uint8_t>(payload.size()), serial};
  f.push_back(fdiCrc8(f.data(), 4));
  if (payload.empty()) return f;
  const std::uint16_t crc = fdiCrc16(payload.data(), payload.size());
  f.push_back(static_cast<std::uint8_t>(crc >> 8));
  f.push_back(static_cast<std::uint8_t>(crc & 0xFF));
  f.insert(f.end(), payload.begin(), payload.end());
  f.push_back(kEnd);
  return f;
}

int FdiLinkParser::takeFrame(const std::function<void(const FdiFrame&)>& on_frame) {
  const std::vector<std::uint8_t>& b = buffer_;
  if (b[0] != kStart) return -1;
  if (b.size() < 5) return 0;
  if (fdiCrc8(b.data(), 4) != b[4]) {
    ++counters_["crc8_error"];
    return -1;
  }
  const std::size_t length = b[2];
  const std::size_t size = length == 0 ? 5 : kHeaderBytes + length + 1;
  if (b.size() < size) return 0;
  if (length > 0) {
    if (b[size - 1] != kEnd) {
      ++counters_["bad_tail"];
      return -1;
    }
    const std::uint16_t crc = static_cast<std::uint16_t>((b[5] << 8) | b[6]);
    if (fdiCrc16(b.data() + kHeaderBytes, length) != crc) {
      ++counters_["crc16_error"];
      return -1;
    }
  }
  FdiFrame frame;
  frame.type = b[1];
  frame.serial = b[3];
  frame.payload.assign(b.begin() + static_cast<std::ptrdiff_t>(kHeaderBytes),
                       b.begin() + static_cast<std::ptrdiff_t>(kHeaderBytes + length));
  if (length == 0) frame.payload.clear();
  if (last_serial_) {
    const int gap = static_cast<std::uint8_t>(frame.serial - *last_serial_ - 1);
    counters_["lost_frames"] += gap;
  }
  last_serial_ = frame.serial;
  ++counters_["frames"];
  on_frame(frame);
  return static_cast<int>(size);
}

void FdiLinkParser::push(const std::uint8_t* data, std::size_t size,
                         const std::function<void(const FdiFrame&)>& on_frame) {
  buffer_.insert(buffer_.end(), data, data + size);
  std::size_t skipped = 0;
  while (!buffer_.empty()) {
    const int taken = takeFrame(on_frame);
    if (taken == 0) break;
    // A frame, or a byte that starts none: drop it and look again from the next one.
    const std::size_t n = taken > 0 ? static_cast<std::size_t>(taken) : 1;
    if (taken < 0) ++skipped;
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(n));
  }
  if (buffer_.size() > kMaxBuffered) {  // unreachable for valid lengths; a guard on the bound all the same
    skipped += buffer_.size();
    buffer_.clear();
  }
  if (skipped) counters_["skipped_bytes"] += static_cast<std::int64_t>(skipped);
}

std::optional<FdiImu> decodeFdiImu(const std::vector<std::uint8_t>& payload) {
  if (payload.size() != kFdiImuPayloadBytes) return std::nullopt;
  double v[6];
  if (!readFloats(payload.data(), 6, v)) return std::nullopt;
  FdiImu imu;
  imu.gyro = {v[0], v[1], v[2]};
  imu.accel = {v[3], v[4], v[5]};
  imu.device_us = readInt64(payload.data() + 48);
  return imu;
}

std::optional<FdiAhrs> decodeFdiAhrs(const std::vector<std::uint8_t>& payload) {
  if (payload.size() != kFdiAhrsPayloadBytes) return std::nullopt;
  double q[4];
  if (!readFloats(payload.data() + 24, 4, q)) return std::nullopt;
  const Eigen::Quaterniond orientation(q[0], q[1], q[2], q[3]);
  if (std::abs(orientation.norm() - 1.0) > 1e-2) return std::nullopt;
  FdiAhrs ahrs;
  ahrs.orientation = orientation.normalized();
  ahrs.device_us = readInt64(payload.data() + 40);
  return ahrs;
}

std::vector<std::uint8_t> encodeFdiImu(const FdiImu& imu) {
  std::vector<std::uint8_t> p;
  for (int i = 0; i < 3; ++i) writeFloat(p, static_cast<float>(imu.gyro[i]));
  for (int i = 0; i < 3; ++i) writeFloat(p, static_cast<float>(imu.accel[i]));
  for (int i = 0; i < 6; ++i) writeFloat(p, 0.0f);  // magnetometer, temperatures, pressure: not used
  writeInt64(p, imu.device_us);
  return p;
}

std::vector<std::uint8_t> encodeFdiAhrs(const FdiAhrs& ahrs) {
  std::vector<std::uint8_t> p;
  for (int i = 0; i < 6; ++i) writeFloat(p, 0.0f);  // rates and Euler angles: the quaternion says it all
  const Eigen::Quaterniond& q = ahrs.orientation;
  for (double c : {q.w(), q.x(), q.y(), q.z()}) writeFloat(p, static_cast<float>(c));
  writeInt64(p, ahrs.device_us);
  return p;
}

}  // namespace adit::drivers
