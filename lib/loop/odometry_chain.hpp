// The uncorrected keyframe poses from the mapper and the covariance of each odometry step between them:
// what the graph's uncertainty between two keyframes is before any loop, used to gate loop candidates.
#pragma once

#include "core/shared_append_vector.hpp"
#include "loop/se3.hpp"

#include <vector>

namespace adit {

class OdometryChain {
 public:
  // First call: the first keyframe (its covariance is ignored). Later calls: the step from the previous
  // keyframe, covariance in the new keyframe's frame (right perturbation of T_previous_new).
  void add(const Eigen::Isometry3d& T_world_keyframe, const Matrix6d& step_covariance);
  int size() const { return static_cast<int>(poses_.size()); }
  const Eigen::Isometry3d& pose(int k) const { return poses_[static_cast<std::size_t>(k)]; }
  // Covariance of the step k-1 -> k as added (k = 0: what was given for the first pose).
  const Matrix6d& stepCovariance(int k) const { return step_covariances_[static_cast<std::size_t>(k)]; }

  // Covariance of T_a_b accumulated along the chain a..b (a < b), expressed in b's frame:
  // sum over steps k in (a, b] of Ad(T_b_k) Sigma_k Ad(T_b_k)^T. Zero when a >= b.
  Matrix6d covarianceBetween(int a, int b) const;

 private:
  // Shared by copies (a loop job's snapshot), which then cost a pointer per 512 keyframes.
  SharedAppendVector<Eigen::Isometry3d> poses_;
  SharedAppendVector<Matrix6d> step_covariances_;  // [k]: step k-1 -> k ([0] unused)
};

// Chi-square of a loop measurement Z = T_match_query against the graph's current estimate T_match_query_graph,
// given the chain covariance between the two keyframes and the loop's own covariance.
double loopChi2(const Eigen::Isometry3d& Z, const Eigen::Isometry3d& T_match_query_graph,
                const Matrix6d& chain_covariance, const Matrix6d& loop_covariance);

// A lower bound on loopChi2 for every fit a verifier could return, known before it runs: the fit puts the query
// within max_fit_distance of the match keyframe, while the graph puts it graph_distance away. With
// partial_axis_offset > 0 the fit may also be a partial loop (loop_job.cpp): free along an axis a that the graph
// crosses by at most that offset, its residual projected off a and its covariance inflated along a, so the
// bound holds for those too (docs/measurements.md, "The odometry gate before ICP": the derivation). loop_covariance is the full loop's.
// 0 when the distances do not separate the two.
double loopChi2LowerBound(double graph_distance, double max_fit_distance, double partial_axis_offset,
                          const Matrix6d& chain_covariance, const Matrix6d& loop_covariance);

// Chi-square of the cycle closed by two loops (m_a -> q_a and m_b -> q_b): the query-side relative pose must
// equal Z_a^-1 * T_ma_mb * Z_b.
double pairChi2(const Eigen::Isometry3d& Z_a, const Eigen::Isometry3d& Z_b, const Eigen::Isometry3d& T_ma_mb,
                const Eigen::Isometry3d& T_qa_qb, const Matrix6d& cycle_covariance);

}  // namespace adit
