#include "msg/point_set.hpp"

#include <algorithm>
#include <cmath>

namespace adit::msg {
namespace {

// The int16 count of each coordinate: v / scale rounded half away from zero, clamped to +-32767. Written without
// branches or libm calls over a plain array so that the compiler vectorises it (it runs for every point of
// every set each stage publishes). Clamping before rounding gives what rounding and then clamping gave: a
// quotient beyond +-32767 lands on +-32767 either way. Callers pass finite coordinates only.
void countsOf(const float* v, std::size_t n, float scale, std::int16_t* out) {
  for (std::size_t i = 0; i < n; ++i) {
    const float q = std::min(std::max(v[i] / scale, -32767.0f), 32767.0f);
    const auto t = static_cast<std::int32_t>(q);  // truncation toward zero
    const float rest = q - static_cast<float>(t);
    out[i] = static_cast<std::int16_t>(t + static_cast<std::int32_t>(rest >= 0.5f) -
                                       static_cast<std::int32_t>(rest <= -0.5f));
  }
}

}  // namespace

adit::point_set_t emptyPointSet() {
  adit::point_set_t s;
  s.scale = kPointSetScale;
  s.num_points = s.num_rings = s.num_times = 0;
  return s;
}

float pointSetScale(const std::vector<LidarPoint>& points) {
  float largest = 0.0f;
  for (const LidarPoint& p : points)
    if (p.p.allFinite()) largest = std::max(largest, p.p.cwiseAbs().maxCoeff());
  return std::max(kPointSetScale, largest / 32767.0f);
}

adit::point_set_t toPointSet(const std::vector<LidarPoint>& points, PointSetFields fields) {
  adit::point_set_t s = emptyPointSet();
  std::vector<const LidarPoint*> kept;
  kept.reserve(points.size());
  for (const LidarPoint& p : points)
    if (p.p.allFinite()) kept.push_back(&p);
  s.scale = std::max(pointSetScale(points), fields.min_scale);
  const std::size_t n = kept.size();
  s.num_points = static_cast<std::int32_t>(n);
  s.x.resize(n);
  s.y.resize(n);
  s.z.resize(n);
  std::vector<float> axis(n);
  const auto quantise = [&](int a, std::vector<std::int16_t>& to) {
    for (std::size_t i = 0; i < n; ++i) axis[i] = kept[i]->p[a];
    countsOf(axis.data(), n, s.scale, to.data());
  };
  quantise(0, s.x);
  quantise(1, s.y);
  quantise(2, s.z);
  if (fields.rings) {
    s.num_rings = s.num_points;
    s.ring.resize(n);
    for (std::size_t i = 0; i < n; ++i) s.ring[i] = static_cast<std::uint8_t>(std::min<int>(kept[i]->ring, 255));
  }
  if (fields.times) {
    s.num_times = s.num_points;
    s.dt.resize(n);
    for (std::size_t i = 0; i < n; ++i) s.dt[i] = kept[i]->dt;
  }
  return s;
}

std::vector<LidarPoint> fromPointSet(const adit::point_set_t& s) {
  if (!(s.scale > 0.0f && std::isfinite(s.scale)) || s.num_points <= 0) return {};
  const auto n = static_cast<std::size_t>(s.num_points);
  const bool rings = s.num_rings == s.num_points, times = s.num_times == s.num_points;
  std::vector<LidarPoint> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    LidarPoint& p = out[i];
    p.p = Eigen::Vector3f(static_cast<float>(s.x[i]), static_cast<float>(s.y[i]), static_cast<float>(s.z[i])) * s.scale;
    if (rings) p.ring = s.ring[i];
    if (times) p.dt = s.dt[i];
  }
  return out;
}

}  // namespace adit::msg
