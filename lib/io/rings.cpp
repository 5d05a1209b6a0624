#include "io/rings.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

namespace adit::io {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

std::vector<double> degreesToRadians(std::vector<double> deg) {
  for (double& d : deg) d *= kDegToRad;
  return deg;
}

bool isValid(const LidarPoint& pt) { return pt.p.allFinite() && (pt.p.x() != 0.0f || pt.p.y() != 0.0f || pt.p.z() != 0.0f); }

double elevationOf(const LidarPoint& pt) {
  return std::atan2(static_cast<double>(pt.p.z()), std::hypot(static_cast<double>(pt.p.x()), static_cast<double>(pt.p.y())));
}

// Index of the element of the ascending `table` nearest to `value`.
int nearestIndex(const std::vector<double>& table, double value) {
  const auto it = std::lower_bound(table.begin(), table.end(), value);
  if (it == table.begin()) return 0;
  if (it == table.end()) return static_cast<int>(table.size()) - 1;
  const auto below = it - 1;
  return static_cast<int>((value - *below <= *it - value) ? below - table.begin() : it - table.begin());
}

}  // namespace

std::vector<double> vlp16Elevations() { return uniformElevations(16, -15.0 * kDegToRad, 15.0 * kDegToRad); }

std::vector<double> rs16Elevations() { return uniformElevations(16, -15.0 * kDegToRad, 15.0 * kDegToRad); }

std::vector<double> hdl64Elevations() {
  std::vector<double> deg;
  for (int k = 31; k >= 0; --k) deg.push_back(-8.83 - 0.5 * k);       // lower block, -24.33 .. -8.83
  for (int k = 31; k >= 0; --k) deg.push_back(2.0 - k / 3.0);          // upper block, -8.33 .. +2.0
  return degreesToRadians(deg);
}

std::vector<double> uniformElevations(int num_beams, double min_rad, double max_rad) {
  std::vector<double> out;
  if (num_beams <= 0) return out;
  if (num_beams == 1) return {min_rad};
  const double step = (max_rad - min_rad) / (num_beams - 1);
  for (int k = 0; k < num_beams; ++k) out.push_back(min_rad + step * k);
  return out;
}

std::vector<double> beamTable(const std::string& sensor) {
  if (sensor == "vlp16") return vlp16Elevations();
  if (sensor == "rs16") return rs16Elevations();
  if (sensor == "hdl64") return hdl64Elevations();
  return {};
}

RingAssignmentStats assignRingsByElevation(std::vector<LidarPoint>& points, const std::vector<double>& elevations,
                                           double tolerance_rad) {
  RingAssignmentStats stats;
  stats.num_beams = static_cast<int>(elevations.size());
  stats.per_ring.assign(elevations.size(), 0);
  if (elevations.empty()) return stats;
  for (LidarPoint& pt : points) {
    if (!isValid(pt)) {
      pt.ring = 0;
      ++stats.invalid_points;
      continue;
    }
    const double elevation = elevationOf(pt);
    const int ring = nearestIndex(elevations, elevation);
    if (std::abs(elevation - elevations[static_cast<size_t>(ring)]) > tolerance_rad) ++stats.far_from_beam;
    pt.ring = static_cast<std::uint16_t>(ring);
    ++stats.per_ring[static_cast<size_t>(ring)];
  }
  return stats;
}

namespace {

// Row index of every point of a cloud stored beam by beam; returns the number of rows.
int scanOrderRows(const std::vector<LidarPoint>& points, int min_row_points, std::vector<int>& row_of) {
  row_of.assign(points.size(), 0);
  if (points.empty()) return 0;
  int row = 0;
  int points_in_row = 0;
  bool have_previous = false;
  double previous_azimuth = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    const LidarPoint& pt = points[i];
    if (std::isfinite(pt.p.x()) && std::isfinite(pt.p.y()) && (pt.p.x() != 0.0f || pt.p.y() != 0.0f)) {
      const double azimuth = std::atan2(static_cast<double>(pt.p.y()), static_cast<double>(pt.p.x()));
      // Crossing the front from the right (small negative -> small non-negative azimuth): a new row.
      // The 90 deg bound rejects the +-180 deg wrap at the back, which lies inside every row.
      const bool crosses_front = have_previous && previous_azimuth < 0.0 && azimuth >= 0.0 &&
                                 azimuth - previous_azimuth < M_PI / 2;
      if (crosses_front && points_in_row >= min_row_points) {
        ++row;
        points_in_row = 0;
      }
      previous_azimuth = azimuth;
      have_previous = true;
    }
    row_of[i] = row;  // an invalid point stays in the row it was stored in
    ++points_in_row;
  }
  return row + 1;
}

}  // namespace

int countScanOrderRows(const std::vector<LidarPoint>& points, int min_row_points) {
  std::vector<int> row_of;
  return scanOrderRows(points, min_row_points, row_of);
}

std::vector<double> elevationPeaks(const std::vector<LidarPoint>& points) {
  constexpr double kBinDeg = 0.05, kMaxDeg = 45.0;
  const int bins = static_cast<int>(2 * kMaxDeg / kBinDeg);
  std::vector<double> count(static_cast<std::size_t>(bins), 0.0), sum(count.size(), 0.0);
  for (const LidarPoint& pt : points) {
    if (!pt.p.allFinite()) continue;
    const double h = std::hypot(static_cast<double>(pt.p.x()), static_cast<double>(pt.p.y()));
    if (h <= 0.0) continue;
    const double e = std::atan2(static_cast<double>(pt.p.z()), h) * 180.0 / M_PI;
    const int b = static_cast<int>(std::floor((e + kMaxDeg) / kBinDeg));
    if (b < 0 || b >= bins) continue;
    count[static_cast<std::size_t>(b)] += 1.0;
    sum[static_cast<std::size_t>(b)] += e;
  }
  std::vector<double> smooth(count.size(), 0.0);
  for (int b = 0; b < bins; ++b)
    for (int d = -1; d <= 1; ++d)
      if (b + d >= 0 && b + d < bins) smooth[static_cast<std::size_t>(b)] += count[static_cast<std::size_t>(b + d)] / 3.0;
  double total = 0.0;
  int filled = 0;
  for (double c : smooth)
    if (c > 0) {
      total += c;
      ++filled;
    }
  std::vector<double> peaks;
  if (filled == 0) return peaks;
  const double threshold = 0.2 * total / filled;
  double run_count = 0.0, run_sum = 0.0;
  for (int b = 0; b <= bins; ++b) {
    if (b < bins && smooth[static_cast<std::size_t>(b)] > threshold) {
      run_count += count[static_cast<std::size_t>(b)];
      run_sum += sum[static_cast<std::size_t>(b)];
    } else if (run_count > 0) {
      peaks.push_back(run_sum / run_count * M_PI / 180.0);
      run_count = run_sum = 0.0;
    }
  }
  return peaks;
}

int detectBeamCount(const std::vector<LidarPoint>& points) {
  const int rows = countScanOrderRows(points);
  for (int fan : {16, 32, 40, 64, 128})
    if (rows == fan) return rows;
  const int peaks = static_cast<int>(elevationPeaks(points).size());
  return peaks >= 4 && peaks <= 128 ? peaks : 0;
}

bool assignRingsByScanOrder(std::vector<LidarPoint>& points, int num_beams, int min_row_points) {
  if (num_beams <= 0 || points.empty()) return false;
  std::vector<int> row_of;
  const int rows = scanOrderRows(points, min_row_points, row_of);
  if (rows != num_beams) return false;
  for (size_t i = 0; i < points.size(); ++i) points[i].ring = static_cast<std::uint16_t>(num_beams - 1 - row_of[i]);
  return true;
}

}  // namespace adit::io

namespace adit::io {

// Fewer distinct rings than this say nothing reliable about the numbering's direction.
constexpr std::size_t kMinRingsToOrient = 4;

bool orientRingsBottomUp(std::vector<LidarPoint>& points) {
  std::map<int, std::pair<double, int>> per_ring;  // ring -> (sum of elevations, points)
  for (const LidarPoint& p : points) {
    const double horizontal = std::hypot(p.p.x(), p.p.y());
    if (!p.p.allFinite() || (horizontal == 0.0 && p.p.z() == 0.0f)) continue;
    auto& [sum, n] = per_ring[p.ring];
    sum += std::atan2(static_cast<double>(p.p.z()), horizontal);
    ++n;
  }
  // Only a clear top-down numbering is flipped: every ring's mean elevation below the previous ring's.
  // Rings that are not ordered by elevation at all (a synthetic or permuted numbering) stay as they are.
  if (per_ring.size() < kMinRingsToOrient) return false;
  double previous = std::numeric_limits<double>::infinity();
  for (const auto& [ring, sum_n] : per_ring) {
    const double mean = sum_n.first / sum_n.second;
    if (!(mean < previous)) return false;
    previous = mean;
  }
  const int hi = per_ring.rbegin()->first;
  for (LidarPoint& p : points) p.ring = static_cast<std::uint16_t>(hi - p.ring);
  return true;
}

}  // namespace adit::io
