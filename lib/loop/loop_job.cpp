#include "loop/loop_job.hpp"

#include "loop/loop_consensus.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>

namespace adit {
namespace {

// What a job decides with: its snapshot, the book and the configuration.
class JobRun {
 public:
  JobRun(const LoopJob& job, LoopBook& book, const LoopCloserConfig& config, PlaneTargetCache* targets)
      : job_(job), book_(book), config_(config), targets_(targets ? targets : &unkept_) {}

  LoopJobOutcome run() {
    LoopJobOutcome out;
    out.query = job_.query;
    if (job_.query - book_.last_loop_query >= config_.cooldown_keyframes) {
      ++counts_.queries;
      out.loops = detect();
    }
    if (!out.loops.empty()) optimize(out);
    counts_.pending = static_cast<int>(book_.pending.size());
    out.book = book_;
    out.counts = counts_;
    return out;
  }

 private:
  std::vector<LoopConstraint> detect() {
    for (const LoopCandidateSnapshot& c : job_.candidates) {
      ++counts_.candidates;
      const std::optional<LoopConstraint> loop = verify(c);
      if (!loop) continue;
      std::vector<LoopConstraint> accepted = admit(*loop);
      if (!accepted.empty()) {
        book_.last_loop_query = job_.query;
        counts_.accepted += static_cast<int>(accepted.size());
        counts_.partial_loops += static_cast<int>(std::count_if(accepted.begin(), accepted.end(), isPartialLoop));
        book_.accepted.insert(book_.accepted.end(), accepted.begin(), accepted.end());
      }
      return accepted;  // one verified loop per keyframe is enough
    }
    return {};
  }

  std::optional<LoopConstraint> verify(const LoopCandidateSnapshot& c) {
    // Seeds: the Scan Context yaw, then the graph's current relative pose (then LinK3D's, see verification()).
    const int m = c.candidate.index;
    const Eigen::Isometry3d T_graph = job_.graph.pose(m).inverse() * job_.graph.pose(job_.query);
    // The graph's uncertainty between the two keyframes, summed along the chain once for the gate and the fits.
    const Matrix6d chain = job_.chain.covarianceBetween(m, job_.query);
    if (gateRefusesEveryFit(c, T_graph, chain)) {
      ++counts_.rejected_odometry;
      return std::nullopt;
    }
    std::vector<Eigen::Isometry3d> seeds(2);
    seeds[kScanContextSeed] =
        scanContextSeed(job_.query_uncorrected, c.match_uncorrected, c.candidate.yaw, config_.level_scan_context);
    seeds[kGraphSeed] = T_graph;
    const std::vector<LoopVerification> fits = verification(c, seeds);
    if (fits.size() == 1) {
      const Judged j = judge(c, fits[0], T_graph, chain);
      if (j.rejection) ++*j.rejection;
      return j.loop;
    }
    // Two accepted fits in different places (the keypoints' and the other seeds', or the Scan Context seed's
    // and the graph's): the odometry may tell them apart; if it allows both, the place is aliased and neither
    // is trusted.
    const Judged a = judge(c, fits[0], T_graph, chain), b = judge(c, fits[1], T_graph, chain);
    if (a.loop && b.loop) {
      ++counts_.rejected_ambiguous;
      return std::nullopt;
    }
    // The graph's fit only checks the Scan Context seed's: where the gate refuses the latter, a fit that ICP
    // found by starting where the graph already puts the query is not taken in its place (along a weakly
    // observed axis it stays near that belief: a featureless roadway's fit 1 m off passed as a full loop).
    if (fits[1].seed == kGraphSeed) {
      if (a.rejection) ++*a.rejection;
      return a.loop;
    }
    if (!a.loop && !b.loop) ++counts_.rejected_odometry;
    return a.loop ? a.loop : b.loop;
  }

  // True when the odometry gate would refuse any fit the verifier could accept (judge()), so ICP need not run:
  // most Scan Context candidates of a long aliased roadway lie tens to hundreds of metres away by the graph
  // (on issue 16's 700 s drive 1,109 of 1,194 fits were refused there after a full ICP). An accepted or
  // degenerate fit has inliers, so some query point lands within the fine correspondence distance of a submap
  // point: the query's origin lies within that distance plus the two clouds' extents of the match keyframe.
  bool gateRefusesEveryFit(const LoopCandidateSnapshot& c, const Eigen::Isometry3d& T_graph, const Matrix6d& chain) {
    const double ratio = config_.verifier.min_inlier_ratio;
    if (!(ratio > 0.0)) return false;  // a fit without inliers could be anywhere
    if (!query_reach_) query_reach_ = innerQueryRadius(querySourceOnce(), ratio);
    double submap_extent = 0.0;
    for (std::size_t i = 0; i < c.neighbourhood.clouds.size() && i < c.neighbourhood.T_match_cloud.size(); ++i)
      submap_extent = std::max(submap_extent, c.neighbourhood.T_match_cloud[i].translation().norm() +
                                                  c.neighbourhood.clouds[i].maxNorm());
    const double reach = *query_reach_ + submap_extent + config_.verifier.icp.fine_correspondence_distance;
    const double offset = config_.partial_loops ? config_.partial_loop_max_axis_offset : 0.0;
    const double bound =
        loopChi2LowerBound(T_graph.translation().norm(), reach, offset, chain, loopMeasurementCovariance(config_));
    return bound > config_.max_odometry_chi2;
  }

  // A radius within which lie more of the source's points than a fit may leave without inliers: at least one
  // inlier of any fit the verifier accepts is that close to the query's origin.
  static double innerQueryRadius(const std::vector<Eigen::Vector3f>& source, double min_inlier_ratio) {
    if (source.empty()) return 0.0;
    std::vector<float> norms;
    norms.reserve(source.size());
    for (const Eigen::Vector3f& p : source) norms.push_back(p.norm());
    // One point more than (1 - ratio) of them (and one more for the rounding of the ratio's comparison).
    const double outside = std::floor((1.0 - min_inlier_ratio) * static_cast<double>(norms.size())) + 1.0;
    const auto k = static_cast<std::size_t>(std::min(outside, static_cast<double>(norms.size() - 1)));
    std::nth_element(norms.begin(), norms.begin() + static_cast<std::ptrdiff_t>(k), norms.end());
    return static_cast<double>(norms[k]) * (1.0 + 1e-6);
  }

  // The ICP source of the job's query, made once for all its candidates.
  const std::vector<Eigen::Vector3f>& querySourceOnce() {
    if (!query_source_) query_source_ = querySource(job_.query_cloud.decode(), config_.verifier);
    return *query_source_;
  }

  // A verified fit as a loop constraint, or the counter of why it is none.
  struct Judged {
    std::optional<LoopConstraint> loop;
    int* rejection = nullptr;
  };

  Judged judge(const LoopCandidateSnapshot& c, const LoopVerification& v, const Eigen::Isometry3d& T_graph,
               const Matrix6d& chain) {
    const int m = c.candidate.index;
    const bool partial = v.verdict == LoopVerdict::kDegenerate && config_.partial_loops &&
                         pinsAllButOneTranslation(v.icp.observability, config_.verifier);
    if (v.verdict == LoopVerdict::kDegenerate && !partial) return {std::nullopt, &counts_.rejected_degenerate};
    if (v.verdict != LoopVerdict::kAccepted && !partial) return {std::nullopt, &counts_.rejected_fitness};
    Eigen::Isometry3d T_match_query = v.T_match_query;
    Matrix6d loop_cov = loopMeasurementCovariance(config_);
    if (partial) {
      // The fit's free axis is in the match keyframe's frame (left perturbation), like the translation of
      // T_match_query; loop residuals are in the query's.
      const Eigen::Vector3d axis = v.icp.observability.weakestTranslation().normalized();
      const double graph_along = axis.dot(T_graph.translation());
      if (!(std::abs(graph_along) <= config_.partial_loop_max_axis_offset))
        return {std::nullopt, &counts_.rejected_degenerate};
      T_match_query.translation() += axis * (graph_along - axis.dot(T_match_query.translation()));
      loop_cov = partialLoopCovariance(config_, T_match_query.linear().transpose() * axis);
    }
    const double chi2 = loopChi2(T_match_query, T_graph, chain, loop_cov);
    if (!(chi2 <= config_.max_odometry_chi2)) return {std::nullopt, &counts_.rejected_odometry};
    LoopConstraint loop;
    loop.query_index = job_.query;
    loop.match_index = m;
    loop.query_utime = job_.query_utime;
    loop.match_utime = c.match_utime;
    loop.T_match_query = T_match_query;
    loop.information = loop_cov.inverse();
    loop.scan_context_distance = c.candidate.distance;
    loop.scan_context_yaw = c.candidate.yaw;
    loop.fitness = v.icp.rms;
    loop.inlier_ratio = v.icp.inlier_ratio;
    return {loop, nullptr};
  }

  // ICP of the query against the candidate's submap from the seeds in order, then the LinK3D keypoints' say.
  // Where no seed fits: ICP from the keypoints' seed. Where a seed gave an accepted fit and the keypoints put the
  // query elsewhere: ICP from theirs as well; a second accepted fit away from the first is returned beside it
  // (two fits: an aliased place unless the odometry rules one out). A keypoint seed whose ICP does not fit is
  // outvoted by the geometry. A degenerate fit is left as it is (sliding along its free axis fits everywhere; a
  // partial loop takes that axis from the graph). The clouds are decoded here, on the worker: the main thread
  // only copies the compact clouds into the job.
  std::vector<LoopVerification> verification(const LoopCandidateSnapshot& c, const std::vector<Eigen::Isometry3d>& seeds) {
    bool kept = false;
    const std::shared_ptr<const PlaneTarget> target = targets_->target(c.neighbourhood, config_.verifier, &kept);
    if (kept) ++counts_.submaps_reused;
    const std::vector<Eigen::Vector3f>& source = querySourceOnce();
    const LoopVerification v = verifyLoopAgainst(*target, source, seeds, config_.verifier);
    const KeypointSeedConfig& k = config_.keypoints;
    // A fit from the Scan Context seed away from where the graph puts the query is tried from the graph's seed
    // as well (the seeds stop at the first tight fit): on a roadway that looks the same a few metres on, ICP
    // from the Scan Context seed (the same place) fits tightly where the candidate keyframe is, not where the
    // query is. A second tight fit makes the place aliased unless the odometry rules the Scan Context seed's
    // out (verify(), which never takes the graph's fit in its place).
    // Measured on issue 16's 700 s drive: two loops 6 m off, one arch spacing, fitness 0.041 m, let through by
    // 2.9 m of chain uncertainty along the roadway.
    if (v.verdict == LoopVerdict::kAccepted && v.seed != kGraphSeed && !posesAgree(v.T_match_query, seeds[kGraphSeed], k)) {
      LoopVerification g = verifyLoopAgainst(*target, source, {seeds[kGraphSeed]}, config_.verifier);
      g.seed = kGraphSeed;
      if (g.verdict == LoopVerdict::kAccepted && !posesAgree(v.T_match_query, g.T_match_query, k)) return {v, g};
    }
    if (!k.use || !job_.query_keypoints || v.verdict == LoopVerdict::kTooFewPoints ||
        v.verdict == LoopVerdict::kDegenerate)
      return {v};
    const KeypointSeed seed =
        keypointSeed(*job_.query_keypoints, c.neighbourhood_keypoints, c.neighbourhood.T_match_cloud, k);
    if (!seed.ok) return {v};
    ++counts_.keypoint_seeds;
    const bool accepted = v.verdict == LoopVerdict::kAccepted;
    if (accepted && posesAgree(v.T_match_query, seed.T_match_query, k)) return {v};
    LoopVerification w = verifyLoopAgainst(*target, source, {seed.T_match_query}, config_.verifier);
    w.seed = static_cast<int>(seeds.size());
    if (!accepted) {
      const bool found = w.verdict == LoopVerdict::kAccepted || w.verdict == LoopVerdict::kDegenerate;
      if (found) ++counts_.keypoint_loops;
      return {found ? w : v};
    }
    if (w.verdict != LoopVerdict::kAccepted || posesAgree(v.T_match_query, w.T_match_query, k)) return {v};
    return {v, w};
  }

  bool pairConsistent(const LoopConstraint& a, const LoopConstraint& b) const {
    const auto chain = [this](int i, int j) {
      return i <= j ? job_.chain.covarianceBetween(i, j) : job_.chain.covarianceBetween(j, i);
    };
    const Matrix6d cov =
        chain(a.query_index, b.query_index) + chain(a.match_index, b.match_index) +
        a.information.inverse() + b.information.inverse();
    const PoseGraph& g = job_.graph;
    const Eigen::Isometry3d T_ma_mb = g.pose(a.match_index).inverse() * g.pose(b.match_index);
    const Eigen::Isometry3d T_qa_qb = g.pose(a.query_index).inverse() * g.pose(b.query_index);
    return pairChi2(a.T_match_query, b.T_match_query, T_ma_mb, T_qa_qb, cov) <= config_.max_pair_chi2;
  }

  // Decides whether a verified loop joins the graph now, waits for a consistent partner, or is rejected.
  std::vector<LoopConstraint> admit(const LoopConstraint& loop) {
    const auto near = [this, &loop](const LoopConstraint& other) {
      return std::abs(other.query_index - loop.query_index) <= config_.consistency_window;
    };
    bool any_near_accepted = false, consistent_with_accepted = false;
    for (const LoopConstraint& a : book_.accepted) {
      if (!near(a)) continue;
      any_near_accepted = true;
      consistent_with_accepted = consistent_with_accepted || pairConsistent(a, loop);
    }
    if (any_near_accepted) {
      if (consistent_with_accepted) return {loop};
      ++counts_.rejected_pairwise;
      return {};
    }
    if (config_.min_consistent_loops <= 1) return {loop};

    auto& pending = book_.pending;
    pending.erase(std::remove_if(pending.begin(), pending.end(), [&](const LoopConstraint& p) { return !near(p); }),
                  pending.end());
    const auto agree = [this](const LoopConstraint& a, const LoopConstraint& b) { return pairConsistent(a, b); };
    Consensus<LoopConstraint> c = seekConsensus(pending, loop, config_.min_consistent_loops, agree);
    if (c.contested) ++counts_.contested;
    pending = std::move(c.pending);
    return std::move(c.accepted);
  }

  // The snapshot's graph with every accepted loop the main thread had not applied yet (this job's and those
  // of earlier jobs still in flight), optimised.
  void optimize(LoopJobOutcome& out) {
    PoseGraph graph = job_.graph;
    for (std::size_t i = job_.applied_loops; i < book_.accepted.size(); ++i) {
      const LoopConstraint& loop = book_.accepted[i];
      graph.addLoopEdge(loop.match_index, loop.query_index, loop.T_match_query, loop.information);
    }
    graph.optimize(config_.graph);
    ++counts_.optimizations;
    out.optimized = true;
    out.poses = graph.poses();
  }

  static constexpr int kScanContextSeed = 0, kGraphSeed = 1;  // verify()'s seeds, tried in this order

  const LoopJob& job_;
  LoopBook& book_;
  const LoopCloserConfig& config_;
  PlaneTargetCache unkept_{0};  // no cache given: every target built afresh
  PlaneTargetCache* targets_;
  LoopCloserStats counts_;
  std::optional<std::vector<Eigen::Vector3f>> query_source_;  // querySourceOnce()
  std::optional<double> query_reach_;                          // innerQueryRadius of it, once needed
};

}  // namespace

LoopJobOutcome runLoopJob(const LoopJob& job, LoopBook& book, const LoopCloserConfig& config,
                          PlaneTargetCache* targets) {
  return JobRun(job, book, config, targets).run();
}

LoopScheduler::LoopScheduler(const LoopCloserConfig& config, const LoopBook& book)
    : config_(config), book_(book), worker_(config.worker_thread) {}

void LoopScheduler::submit(LoopJob job, std::int64_t due_utime) {
  auto task = std::make_shared<std::packaged_task<LoopJobOutcome()>>([this, job = std::move(job)] {
    const double cpu0 = threadCpuMs();
    LoopJobOutcome outcome = runLoopJob(job, book_, config_, &targets_);
    // Added before the outcome is handed over, so take() sees every finished job's share.
    if (worker_.threaded()) worker_cpu_.add(threadCpuMs() - cpu0);
    return outcome;
  });
  pending_.push_back({due_utime, task->get_future()});
  worker_.post([task] { (*task)(); });
}

std::vector<LoopJobOutcome> LoopScheduler::take(std::int64_t utime, bool all) {
  std::vector<LoopJobOutcome> due;
  while (!pending_.empty() && (all || pending_.front().due_utime <= utime)) {
    std::future<LoopJobOutcome>& f = pending_.front().outcome;
    // Wall clock for STATUS only: how long the sweep stream waited for the worker.
    const auto start = std::chrono::steady_clock::now();
    f.wait();
    waited_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    due.push_back(f.get());
    pending_.pop_front();
  }
  if (all) targets_.clear();  // no job in flight: the worker does not touch it now
  return due;
}

}  // namespace adit
