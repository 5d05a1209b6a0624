// Little binary writer/reader for state snapshots (checkpoints): fixed-width little-endian fields, length-
// prefixed arrays. The reader never reads past its buffer and never allocates more than the bytes left can
// hold, so a truncated or corrupt snapshot is an error (ByteReader::ok() false), not a crash.
#pragma once

#include <Eigen/Geometry>

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

namespace adit {

class ByteWriter {
 public:
  template <class T>
  void put(T value) {
    static_assert(std::is_arithmetic_v<T>, "plain numbers only");
    const auto* p = reinterpret_cast<const char*>(&value);
    bytes_.append(p, sizeof(T));  // the machines adit runs on are little-endian (x86-64, aarch64)
  }
  void putString(const std::string& s) {
    put<std::uint64_t>(s.size());
    bytes_ += s;
  }
  void putPose(const Eigen::Isometry3d& T) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) put<double>(T(r, c));
  }
  template <class Derived>
  void putMatrix(const Eigen::MatrixBase<Derived>& m) {
    for (Eigen::Index r = 0; r < m.rows(); ++r)
      for (Eigen::Index c = 0; c < m.cols(); ++c) put(m(r, c));
  }
  template <class V>  // Eigen::Vector3f / Vector3d
  void putPoints(const std::vector<V>& points) {
    put<std::uint64_t>(points.size());
    for (const V& p : points) putMatrix(p);
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

class ByteReader {
 public:
  ByteReader(const char* data, std::size_t size) : data_(data), size_(size) {}
  explicit ByteReader(const std::string& s) : ByteReader(s.data(), s.size()) {}

  template <class T>
  T get() {
    static_assert(std::is_arithmetic_v<T>, "plain numbers only");
    T value{};
    if (!take(sizeof(T))) return value;
    std::memcpy(&value, data_ + pos_ - sizeof(T), sizeof(T));
    return value;
  }
  // A count of items of item_bytes each: refused (0, !ok) if the bytes left cannot hold that many.
  std::uint64_t getCount(std::size_t item_bytes) {
    const auto n = get<std::uint64_t>();
    if (!ok_ || (item_bytes > 0 && n > (size_ - pos_) / item_bytes)) {
      ok_ = false;
      return 0;
    }
    return n;
  }
  std::string getString() {
    const auto n = getCount(1);
    if (!take(n)) return {};
    return std::string(data_ + pos_ - n, n);
  }
  Eigen::Isometry3d getPose() {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) T(r, c) = get<double>();
    if (!T.matrix().allFinite()) ok_ = false;
    return T;
  }
  template <class M>  // fixed-size Eigen matrix
  M getMatrix() {
    M m;
    for (Eigen::Index r = 0; r < m.rows(); ++r)
      for (Eigen::Index c = 0; c < m.cols(); ++c) m(r, c) = get<typename M::Scalar>();
    return m;
  }
  template <class V>
  std::vector<V> getPoints() {
    const auto n = getCount(sizeof(typename V::Scalar) * 3);
    std::vector<V> out;
    out.reserve(n);
    for (std::uint64_t i = 0; i < n && ok_; ++i) out.push_back(getMatrix<V>());
    return out;
  }
  bool ok() const { return ok_; }
  bool atEnd() const { return pos_ == size_; }
  std::size_t left() const { return size_ - pos_; }
  void fail() { ok_ = false; }

 private:
  bool take(std::size_t n) {
    if (!ok_ || n > size_ - pos_) {
      ok_ = false;
      return false;
    }
    pos_ += n;
    return true;
  }
  const char* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

}  // namespace adit
