#include "features/link3d_match.hpp"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <random>

namespace adit {

int linK3dScore(const LinK3dDescriptor& x, const LinK3dDescriptor& y, float tolerance) {
  int score = 0;  // branch-free so the loop vectorises: it runs N_a x N_b x 180 times per match
  for (int k = 0; k < kLinK3dBins; ++k)
    score += static_cast<int>((x[k] != 0.0f) & (y[k] != 0.0f) & (std::fabs(x[k] - y[k]) < tolerance));
  return score;
}

std::vector<LinK3dMatch> matchLinK3d(const std::vector<LinK3dDescriptor>& a, const std::vector<LinK3dDescriptor>& b,
                                     const LinK3dConfig& cfg) {
  std::vector<LinK3dMatch> best_for_b(b.size());
  for (int i = 0; i < static_cast<int>(a.size()); ++i) {
    LinK3dMatch best{i, -1, 0};
    for (int j = 0; j < static_cast<int>(b.size()); ++j) {
      const int s = linK3dScore(a[i], b[j], cfg.bin_tolerance);
      if (s > best.score) best = {i, j, s};
    }
    if (best.b < 0 || best.score < cfg.min_score) continue;
    if (best.score > best_for_b[best.b].score) best_for_b[best.b] = best;  // ties keep the lower a
  }
  std::vector<LinK3dMatch> out;
  for (const LinK3dMatch& m : best_for_b)
    if (m.b >= 0) out.push_back(m);
  std::sort(out.begin(), out.end(), [](const LinK3dMatch& x, const LinK3dMatch& y) { return x.a < y.a; });
  return out;
}

std::vector<LinK3dMatch> matchLinK3d(const FeatureSet& a, const FeatureSet& b, const LinK3dConfig& cfg) {
  return matchLinK3d(a.descriptors, b.descriptors, cfg);
}

Eigen::Isometry3d features::fitRigid(const std::vector<Eigen::Vector3f>& ka, const std::vector<Eigen::Vector3f>& kb,
                                     const std::vector<LinK3dMatch>& pairs, const std::vector<double>& weights) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (pairs.size() < 3) return T;
  const auto w = [&](std::size_t k) { return weights.empty() ? 1.0 : weights[k]; };
  double wsum = 0.0;
  Eigen::Vector3d ca = Eigen::Vector3d::Zero(), cb = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    wsum += w(k);
    ca += w(k) * ka[pairs[k].a].cast<double>();
    cb += w(k) * kb[pairs[k].b].cast<double>();
  }
  if (!(wsum > 0.0)) return T;
  ca /= wsum;
  cb /= wsum;
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();  // weighted cross-covariance, b -> a
  for (std::size_t k = 0; k < pairs.size(); ++k)
    H += w(k) * (kb[pairs[k].b].cast<double>() - cb) * (ka[pairs[k].a].cast<double>() - ca).transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;  // no reflection
  T.linear() = svd.matrixV() * D * svd.matrixU().transpose();
  T.translation() = ca - T.linear() * cb;
  return T;
}

namespace {

std::vector<LinK3dMatch> inliersOf(const Eigen::Isometry3d& T, const std::vector<Eigen::Vector3f>& ka,
                                   const std::vector<Eigen::Vector3f>& kb, const std::vector<LinK3dMatch>& m,
                                   float threshold) {
  std::vector<LinK3dMatch> in;
  const double t2 = static_cast<double>(threshold) * threshold;
  for (const LinK3dMatch& x : m)
    if ((T * kb[x.b].cast<double>() - ka[x.a].cast<double>()).squaredNorm() < t2) in.push_back(x);
  return in;
}

// Three pairs span a plane well enough to fix a rotation (triangle not degenerate in either cloud).
bool wellShaped(const std::vector<Eigen::Vector3f>& k, int i, int j, int l, float min_area) {
  return 0.5f * (k[j] - k[i]).cross(k[l] - k[i]).norm() > min_area;
}

}  // namespace

RansacResult estimateTransformRansac(const std::vector<Eigen::Vector3f>& ka, const std::vector<Eigen::Vector3f>& kb,
                                     const std::vector<LinK3dMatch>& matches, const RansacConfig& cfg) {
  RansacResult best;
  const int n = static_cast<int>(matches.size());
  for (const LinK3dMatch& m : matches)
    if (m.a < 0 || m.b < 0 || m.a >= static_cast<int>(ka.size()) || m.b >= static_cast<int>(kb.size())) return best;
  if (n < 3) return best;
  std::mt19937 rng(cfg.seed);
  for (int it = 0; it < cfg.iterations; ++it) {
    const int i = static_cast<int>(rng() % n), j = static_cast<int>(rng() % n), l = static_cast<int>(rng() % n);
    if (i == j || j == l || i == l) continue;
    const LinK3dMatch& mi = matches[i];
    const LinK3dMatch& mj = matches[j];
    const LinK3dMatch& ml = matches[l];
    if (!wellShaped(ka, mi.a, mj.a, ml.a, cfg.min_sample_area) || !wellShaped(kb, mi.b, mj.b, ml.b, cfg.min_sample_area))
      continue;
    const Eigen::Isometry3d T = features::fitRigid(ka, kb, {mi, mj, ml});
    std::vector<LinK3dMatch> in = inliersOf(T, ka, kb, matches, cfg.inlier_threshold);
    if (in.size() > best.inliers.size()) {
      best.T_a_b = T;
      best.inliers = std::move(in);
    }
  }
  if (best.inliers.size() < 3) return RansacResult{};
  // Refinement: the consensus set is refitted with Cauchy weights w = 1 / (1 + (r / robust_scale)^2), so the
  // few centroids that moved (a cluster cut differently in the other sweep) barely pull on the result.
  for (int iteration = 0; iteration < 10; ++iteration) {
    std::vector<double> weights;
    for (const LinK3dMatch& m : best.inliers) {
      const double r = (best.T_a_b * kb[m.b].cast<double>() - ka[m.a].cast<double>()).norm() / std::max(1e-3, static_cast<double>(cfg.robust_scale));
      weights.push_back(1.0 / (1.0 + r * r));
    }
    const Eigen::Isometry3d T = features::fitRigid(ka, kb, best.inliers, weights);
    std::vector<LinK3dMatch> in = inliersOf(T, ka, kb, matches, cfg.inlier_threshold);
    if (in.size() < 3) break;
    best.T_a_b = T;
    best.inliers = std::move(in);
  }
  double sum2 = 0.0;
  for (const LinK3dMatch& m : best.inliers) sum2 += (best.T_a_b * kb[m.b].cast<double>() - ka[m.a].cast<double>()).squaredNorm();
  best.rms = best.inliers.empty() ? 0.0 : std::sqrt(sum2 / best.inliers.size());
  best.ok = static_cast<int>(best.inliers.size()) >= std::max(3, cfg.min_inliers);
  return best;
}

}  // namespace adit
