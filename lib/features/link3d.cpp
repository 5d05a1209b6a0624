#include "features/link3d.hpp"

#include "features/preprocess.hpp"

#include <algorithm>
#include <bitset>
#include <cmath>
#include <limits>

namespace adit::features {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

struct Cluster {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double sum_rxy = 0.0;
  int count = 0;
  std::bitset<kMaxRings> rings;
  double mean_x = 0.0, mean_y = 0.0, mean_rxy = 0.0;  // cached means (compared for every point)

  void add(const LidarPoint& p) {
    Cluster single;
    single.sum = p.p.cast<double>();
    single.sum_rxy = std::sqrt(single.sum.x() * single.sum.x() + single.sum.y() * single.sum.y());
    single.count = 1;
    single.rings.set(p.ring % kMaxRings);
    absorb(single);
  }
  void absorb(const Cluster& o) {
    sum += o.sum;
    sum_rxy += o.sum_rxy;
    count += o.count;
    rings |= o.rings;
    mean_x = sum.x() / count;
    mean_y = sum.y() / count;
    mean_rxy = sum_rxy / count;
  }
  Eigen::Vector3d mean() const { return sum / count; }
};

// Same object: similar horizontal range and horizontal means close. The reference code compares |dx| and
// |dy| separately, which depends on the sensor's yaw; the horizontal distance does not.
bool similar(const Cluster& a, const Cluster& b, float radial_tol, float xy_tol) {
  const double dx = a.mean_x - b.mean_x, dy = a.mean_y - b.mean_y;
  return std::fabs(a.mean_rxy - b.mean_rxy) < radial_tol && dx * dx + dy * dy < static_cast<double>(xy_tol) * xy_tol;
}

// Edge points of each horizontal sector, in cloud order (ring by ring, firing order).
std::vector<std::vector<int>> edgePointsBySector(const RingCloud& c, const PointScores& s, const LinK3dConfig& cfg) {
  const int sectors = std::max(1, cfg.sectors);
  std::vector<std::vector<int>> by_sector(sectors);
  for (std::size_t i = 0; i < c.points.size(); ++i) {
    if (!s.usable[i] || s.smoothness[i] <= cfg.edge_threshold || s.offset[i] <= cfg.edge_min_offset) continue;
    const Eigen::Vector3f& p = c.points[i].p;
    const float rxy = std::sqrt(p.x() * p.x() + p.y() * p.y());
    if (rxy > cfg.max_range || rxy < 1e-3f) continue;
    double a = std::atan2(p.y(), p.x());
    if (a < 0.0) a += kTwoPi;
    by_sector[std::min(sectors - 1, static_cast<int>(a / kTwoPi * sectors))].push_back(static_cast<int>(i));
  }
  return by_sector;
}

// Greedy clustering inside one sector: a point joins the first cluster it agrees with, else starts one.
void clusterSector(const RingCloud& c, const std::vector<int>& idx, const LinK3dConfig& cfg,
                   std::vector<Cluster>& out) {
  const std::size_t first = out.size();
  for (int i : idx) {
    Cluster single;
    single.add(c.points[i]);
    bool joined = false;
    for (std::size_t k = first; k < out.size() && !joined; ++k) {
      if (similar(out[k], single, cfg.cluster_radial_tol, cfg.cluster_xy_tol)) {
        out[k].absorb(single);
        joined = true;
      }
    }
    if (!joined) out.push_back(single);
  }
}

int findRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

void unite(std::vector<int>& parent, int a, int b) {
  a = findRoot(parent, a);
  b = findRoot(parent, b);
  if (a != b) parent[std::max(a, b)] = std::min(a, b);  // root = smallest index: order-independent result
}

// Merges clusters of the same or neighbouring sectors describing one object. Each unordered pair is tested
// once (j > i within a sector, and sector s against s + 1), so no cluster merges with itself.
std::vector<Cluster> mergeNeighbours(const std::vector<Cluster>& cl, const std::vector<int>& sector_begin,
                                     const LinK3dConfig& cfg) {
  const int sectors = static_cast<int>(sector_begin.size()) - 1;
  std::vector<int> parent(cl.size());
  for (std::size_t i = 0; i < cl.size(); ++i) parent[i] = static_cast<int>(i);
  for (int s = 0; s < sectors; ++s) {
    const int next = (s + 1) % sectors;
    for (int i = sector_begin[s]; i < sector_begin[s + 1]; ++i) {
      for (int j = i + 1; j < sector_begin[s + 1]; ++j)
        if (similar(cl[i], cl[j], cfg.merge_radial_tol, cfg.merge_xy_tol)) unite(parent, i, j);
      if (next == s || (sectors == 2 && s == 1)) continue;  // pair already tested
      for (int j = sector_begin[next]; j < sector_begin[next + 1]; ++j)
        if (similar(cl[i], cl[j], cfg.merge_radial_tol, cfg.merge_xy_tol)) unite(parent, i, j);
    }
  }
  std::vector<Cluster> merged;
  std::vector<int> slot(cl.size(), -1);
  for (std::size_t i = 0; i < cl.size(); ++i) {
    const int root = findRoot(parent, static_cast<int>(i));
    if (slot[root] < 0) {
      slot[root] = static_cast<int>(merged.size());
      merged.emplace_back();
    }
    merged[slot[root]].absorb(cl[i]);
  }
  return merged;
}

}  // namespace

std::vector<LinK3dCluster> extractLinK3dClusters(const RingCloud& c, const PointScores& s, const LinK3dConfig& cfg) {
  const std::vector<std::vector<int>> by_sector = edgePointsBySector(c, s, cfg);
  std::vector<Cluster> clusters;
  std::vector<int> sector_begin{0};
  for (const std::vector<int>& idx : by_sector) {
    clusterSector(c, idx, cfg, clusters);
    sector_begin.push_back(static_cast<int>(clusters.size()));
  }
  std::vector<LinK3dCluster> out;
  for (const Cluster& m : mergeNeighbours(clusters, sector_begin, cfg)) {
    const int rings = static_cast<int>(m.rings.count());
    if (m.count < cfg.min_cluster_points || rings < cfg.min_cluster_rings) continue;
    out.push_back({m.mean().cast<float>(), m.count, rings});
  }
  return out;
}

namespace {

// Indices of the (up to) 3 nearest keypoints to i with a defined horizontal direction; ties by index.
std::vector<int> nearestThree(int i, int n, const std::vector<float>& dist, const std::vector<float>& dxy) {
  std::vector<int> cand;
  for (int j = 0; j < n; ++j)
    if (j != i && dxy[i * n + j] > 1e-3f) cand.push_back(j);
  const auto closer = [&](int a, int b) { return dist[i * n + a] < dist[i * n + b] || (dist[i * n + a] == dist[i * n + b] && a < b); };
  const std::size_t k = std::min<std::size_t>(3, cand.size());
  std::partial_sort(cand.begin(), cand.begin() + k, cand.end(), closer);
  cand.resize(k);
  return cand;
}

}  // namespace

std::vector<LinK3dDescriptor> computeLinK3dDescriptors(const std::vector<Eigen::Vector3f>& kp) {
  const int n = static_cast<int>(kp.size());
  std::vector<float> dist(static_cast<std::size_t>(n) * n), dxy(dist.size()), angle(dist.size());
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector3f d = kp[j] - kp[i];
      dist[i * n + j] = d.norm();
      dxy[i * n + j] = std::hypot(d.x(), d.y());
      angle[i * n + j] = std::atan2(d.y(), d.x());
    }
  const double bin_width = kTwoPi / kLinK3dBins;
  std::vector<LinK3dDescriptor> out(n);
  for (int i = 0; i < n; ++i) {
    LinK3dDescriptor& desc = out[i];
    desc.fill(0.0f);
    for (int o : nearestThree(i, n, dist, dxy)) {
      LinK3dDescriptor nearest;
      nearest.fill(std::numeric_limits<float>::infinity());
      for (int j = 0; j < n; ++j) {
        if (j == i || dxy[i * n + j] <= 1e-3f) continue;
        double rel = static_cast<double>(angle[i * n + j]) - angle[i * n + o];  // counter-clockwise from main
        rel -= kTwoPi * std::floor(rel / kTwoPi);
        const int bin = static_cast<int>(std::floor(rel / bin_width + 0.5)) % kLinK3dBins;  // bin 0 centred
        nearest[bin] = std::min(nearest[bin], dist[i * n + j]);
      }
      for (int b = 0; b < kLinK3dBins; ++b)
        if (desc[b] == 0.0f && std::isfinite(nearest[b])) desc[b] = nearest[b];
    }
  }
  return out;
}

}  // namespace adit::features
