#include "view/view_stream.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace adit::view {
namespace {

class Out {
 public:
  explicit Out(FrameType type) { put(static_cast<std::uint8_t>(type)); }
  template <class T>
  Out& put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));  // little-endian machines (x86-64, aarch64), as the page reads
    bytes_.append(b, sizeof(T));
    return *this;
  }
  Out& pose(const Eigen::Isometry3d& T) {
    const Eigen::Quaternionf q(Eigen::Quaterniond(T.rotation()).normalized().cast<float>());
    put(T.translation().x()).put(T.translation().y()).put(T.translation().z());
    return put(q.x()).put(q.y()).put(q.z()).put(q.w());
  }
  Out& raw(const std::string& s) {
    bytes_ += s;
    return *this;
  }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

class In {
 public:
  explicit In(const std::string& b) : b_(b) {}
  template <class T>
  T get() {
    T v{};
    if (pos_ + sizeof(T) > b_.size()) {
      ok_ = false;
      return v;
    }
    std::memcpy(&v, b_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  Eigen::Isometry3d pose() {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const double x = get<double>(), y = get<double>(), z = get<double>();
    const float qx = get<float>(), qy = get<float>(), qz = get<float>(), qw = get<float>();
    T.translation() = Eigen::Vector3d(x, y, z);
    T.linear() = Eigen::Quaterniond(qw, qx, qy, qz).normalized().toRotationMatrix();
    return T;
  }
  // A count of items of `bytes` each that the rest can hold.
  std::uint32_t count(std::size_t bytes) {
    const auto n = get<std::uint32_t>();
    if (!ok_ || n > (b_.size() - pos_) / bytes) ok_ = false;
    return ok_ ? n : 0;
  }
  std::string rest() {
    std::string s = b_.substr(pos_);
    pos_ = b_.size();
    return s;
  }
  bool ok() const { return ok_; }
  bool done() const { return pos_ == b_.size(); }

 private:
  const std::string& b_;
  std::size_t pos_ = 0;
  bool ok_ = true;
};

bool quantisable(const Eigen::Vector3f& p) {
  const float limit = std::numeric_limits<std::int16_t>::max() * kPointScale;
  return p.allFinite() && p.cwiseAbs().maxCoeff() < limit;
}

void putPoint(Out& o, const Eigen::Vector3f& p) {
  for (int k = 0; k < 3; ++k) o.put(static_cast<std::int16_t>(std::lround(p[k] / kPointScale)));
}

Eigen::Vector3f getPoint(In& in) {
  const float x = in.get<std::int16_t>(), y = in.get<std::int16_t>(), z = in.get<std::int16_t>();
  return Eigen::Vector3f(x, y, z) * kPointScale;
}

}  // namespace

std::string encodeSubmap(const Submap& s) {
  Out o(FrameType::Submap);
  o.put(static_cast<std::uint32_t>(s.id)).put(s.version).pose(s.pose);
  std::uint32_t n = 0;
  for (const auto& p : s.points) n += quantisable(p);
  o.put(n);
  for (const auto& p : s.points)
    if (quantisable(p)) putPoint(o, p);
  return std::move(o.bytes());
}

std::string encodeSubmapPose(const Submap& s) {
  Out o(FrameType::SubmapPose);
  o.put(static_cast<std::uint32_t>(s.id)).put(s.version).pose(s.pose);
  return std::move(o.bytes());
}

std::string encodeSweep(const Sweep& sweep, const Eigen::Isometry3d& pose, std::size_t max_points) {
  const std::size_t step = max_points == 0 ? 1 : std::max<std::size_t>(1, (sweep.points.size() + max_points - 1) / max_points);
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < sweep.points.size(); i += step)
    if (quantisable(sweep.points[i])) kept.push_back(i);
  Out o(FrameType::Sweep);
  o.put(sweep.utime).pose(pose).put(static_cast<std::uint32_t>(kept.size()));
  for (const std::size_t i : kept) putPoint(o, sweep.points[i]);
  for (const std::size_t i : kept) {
    const float v = i < sweep.intensity.size() ? sweep.intensity[i] : 0.0f;
    o.put(static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)));
  }
  return std::move(o.bytes());
}

std::string encodeTrajectory(TrajectoryKind kind, bool replace, const std::vector<TimedPose>& poses, std::size_t from) {
  Out o(FrameType::Trajectory);
  o.put(static_cast<std::uint8_t>(kind)).put(static_cast<std::uint8_t>(replace ? 1 : 0));
  const std::size_t n = from < poses.size() ? poses.size() - from : 0;
  o.put(static_cast<std::uint32_t>(n));
  for (std::size_t i = from; i < poses.size(); ++i) {
    const Eigen::Vector3f p = poses[i].pose.translation().cast<float>();
    o.put(p.x()).put(p.y()).put(p.z());
  }
  return std::move(o.bytes());
}

std::string encodeLoops(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& segments) {
  Out o(FrameType::Loops);
  o.put(static_cast<std::uint32_t>(segments.size()));
  for (const auto& [a, b] : segments)
    for (const Eigen::Vector3d& p : {a, b}) o.put(static_cast<float>(p.x())).put(static_cast<float>(p.y())).put(static_cast<float>(p.z()));
  return std::move(o.bytes());
}

std::string encodeRobot(const TimedPose& robot) {
  Out o(FrameType::Robot);
  o.put(robot.utime).pose(robot.pose);
  return std::move(o.bytes());
}

std::string encodeInfo(const std::string& json) { return std::move(Out(FrameType::Info).raw(json).bytes()); }

std::string encodeReset() { return std::move(Out(FrameType::Reset).bytes()); }

bool decodeFrame(const std::string& bytes, DecodedFrame& f) {
  In in(bytes);
  const auto type = in.get<std::uint8_t>();
  if (!in.ok() || type < 1 || type > 8) return false;
  f = DecodedFrame{};
  f.type = static_cast<FrameType>(type);
  switch (f.type) {
    case FrameType::Submap:
    case FrameType::SubmapPose: {
      f.id = in.get<std::uint32_t>();
      f.version = in.get<std::uint32_t>();
      f.pose = in.pose();
      if (f.type == FrameType::Submap) {
        const auto n = in.count(6);
        for (std::uint32_t i = 0; i < n; ++i) f.points.push_back(getPoint(in));
      }
      break;
    }
    case FrameType::Sweep: {
      f.utime = in.get<std::int64_t>();
      f.pose = in.pose();
      const auto n = in.count(7);
      for (std::uint32_t i = 0; i < n; ++i) f.points.push_back(getPoint(in));
      for (std::uint32_t i = 0; i < n; ++i) f.intensity.push_back(in.get<std::uint8_t>());
      break;
    }
    case FrameType::Trajectory: {
      const auto kind = in.get<std::uint8_t>();
      if (kind > static_cast<std::uint8_t>(TrajectoryKind::Keyframes)) return false;
      f.kind = static_cast<TrajectoryKind>(kind);
      f.replace = in.get<std::uint8_t>() != 0;
      const auto n = in.count(12);
      for (std::uint32_t i = 0; i < n; ++i) {
        const float x = in.get<float>(), y = in.get<float>(), z = in.get<float>();
        f.points.emplace_back(x, y, z);
      }
      break;
    }
    case FrameType::Loops: {
      const auto n = in.count(24);
      for (std::uint32_t i = 0; i < n; ++i) {
        Eigen::Vector3f a, b;
        for (int k = 0; k < 3; ++k) a[k] = in.get<float>();
        for (int k = 0; k < 3; ++k) b[k] = in.get<float>();
        f.segments.emplace_back(a, b);
      }
      break;
    }
    case FrameType::Robot:
      f.utime = in.get<std::int64_t>();
      f.pose = in.pose();
      break;
    case FrameType::Info:
      f.json = in.rest();
      break;
    case FrameType::Reset:
      break;
  }
  return in.ok() && in.done();
}

}  // namespace adit::view
