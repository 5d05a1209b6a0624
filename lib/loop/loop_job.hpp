// Loop verification and graph optimisation as a job off the loop closer's main thread.
//
// At a keyframe with Scan Context candidates the loop closer takes a snapshot (the query cloud, each
// candidate's neighbourhood, the pose graph and the odometry chain as they are now) and posts a job. The
// job verifies the candidates by ICP, admits a loop against the loops accepted before it (LoopBook: touched
// only by jobs, which run one after the other in the order posted) and, when loops were accepted, optimises
// its copy of the graph. Its outcome is applied at a fixed point of the input: the first sweep whose sensor
// time is at least loop.apply_delay_s after the keyframe's, waiting for the worker there if it is not done.
// So the output depends on the input alone, never on thread timing, and the worker overlaps the next
// sweeps' keyframes and the other stages (apply_delay_s = 0: applied in the same call, the old schedule).
#pragma once

#include "core/thread_cpu.hpp"
#include "loop/loop_closer.hpp"
#include "loop/place_match.hpp"
#include "loop/plane_target_cache.hpp"
#include "core/serial_worker.hpp"

#include <deque>
#include <future>
#include <vector>

namespace adit {

// The loops a job decides against: every accepted loop (also those the main thread has not applied yet),
// verified loops waiting for a consistent partner, and the query of the newest accepted loop (cooldown).
struct LoopBook {
  std::vector<LoopConstraint> accepted;
  std::vector<LoopConstraint> pending;
  int last_loop_query = -1000000;
};

struct LoopCandidateSnapshot {
  ScanContextCandidate candidate;
  std::int64_t match_utime = 0;
  Eigen::Isometry3d match_uncorrected = Eigen::Isometry3d::Identity();
  CandidateNeighbourhood neighbourhood;  // the candidate's neighbours, each at its graph pose relative to it
  std::vector<KeyframeKeypointsPtr> neighbourhood_keypoints;  // [i]: neighbourhood.clouds[i]'s (loop.keypoints.use)
};

struct LoopJob {
  int query = -1;
  std::int64_t query_utime = 0;
  Eigen::Isometry3d query_uncorrected = Eigen::Isometry3d::Identity();
  CompactCloud query_cloud;
  KeyframeKeypointsPtr query_keypoints;  // null: none
  std::vector<LoopCandidateSnapshot> candidates;  // best first, at most max_verifications, under the threshold
  PoseGraph graph;      // nodes 0..query with the loop edges the main thread has applied
  OdometryChain chain;  // keyframes 0..query
  std::size_t applied_loops = 0;  // loops in `graph` (the first of the book's accepted loops)
};

struct LoopJobOutcome {
  int query = -1;
  std::vector<LoopConstraint> loops;     // accepted by this job
  bool optimized = false;
  std::vector<Eigen::Isometry3d> poses;  // optimised poses of nodes 0..query (when optimized)
  LoopBook book;                         // the book after this job
  LoopCloserStats counts;                // queries, candidates, rejections, accepted, optimizations of this job
};

// `targets`: candidate submaps' ICP targets kept from earlier jobs (null: each built afresh; the same outcome).
LoopJobOutcome runLoopJob(const LoopJob& job, LoopBook& book, const LoopCloserConfig& config,
                          PlaneTargetCache* targets = nullptr);

// Jobs in flight and when each is due. Wall time spent waiting for the worker is kept for STATUS only.
class LoopScheduler {
 public:
  explicit LoopScheduler(const LoopCloserConfig& config, const LoopBook& book = {});
  void submit(LoopJob job, std::int64_t due_utime);
  // Outcomes due at `utime` (all of them when `all`), oldest first; waits for those not finished. With
  // `all` (the run's end, or keyframes about to be merged) the kept ICP targets are dropped too: no job is
  // left to use them, and the corrected map is built next at the end of a run.
  std::vector<LoopJobOutcome> take(std::int64_t utime, bool all = false);
  std::size_t inFlight() const { return pending_.size(); }
  // With no job in flight (after take(all)): the book renumbered by the loop closer (keyframes merged out).
  void replaceBook(LoopBook book) { book_ = std::move(book); }
  double waitedMs() const { return waited_ms_; }
  // CPU time the jobs took on the worker thread (0 without one: they ran in submit(), on the caller's
  // thread): STATUS only. Complete for every job whose outcome take() returned.
  double workerCpuMs() const { return worker_cpu_.ms(); }

 private:
  struct Pending {
    std::int64_t due_utime;
    std::future<LoopJobOutcome> outcome;
  };
  LoopCloserConfig config_;
  LoopBook book_;  // only jobs use it, in the order posted
  // Jobs only, too. Four targets (~1-2 MB each) catch most repeats: a candidate recurs over the next few
  // keyframes while the robot passes the place it resembles.
  PlaneTargetCache targets_{4};
  std::deque<Pending> pending_;
  double waited_ms_ = 0;
  CpuTally worker_cpu_;
  SerialWorker worker_;  // declared last: stopped (its jobs finished) before book_ goes
};

}  // namespace adit
