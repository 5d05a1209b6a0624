#include "msg/point_set.hpp"

#include <algorithm>
#include <cmath>

namespace adit::msg {
namespace {

// std::lround (half away from zero) without the libm call: truncate, then step when the remainder (exact in
// float) reaches one half. The scale keeps |q| <= 32767 for the points that are written, so the
// truncation cannot overflow; anything larger goes to lround as before.
long roundHalfAway(float q) {
  if (!(std::fabs(q) < 1e9f)) return std::lround(q);
  const long t = static_cast<long>(q);
  const float rest = q - static_cast<float>(t);
  return rest >= 0.5f ? t + 1 : rest <= -0.5f ? t - 1 : t;
}

std::int16_t count(float v, float scale) {
  return static_cast<std::int16_t>(std::clamp(roundHalfAway(v / scale), -32767L, 32767L));
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
  for (std::size_t i = 0; i < n; ++i) {
    s.x[i] = count(kept[i]->p.x(), s.scale);
    s.y[i] = count(kept[i]->p.y(), s.scale);
    s.z[i] = count(kept[i]->p.z(), s.scale);
  }
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
