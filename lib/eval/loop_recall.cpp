#include "eval/loop_recall.hpp"

#include <algorithm>

namespace adit::eval {
namespace {

struct Sample {
  std::int64_t utime;
  Eigen::Vector3d position;
  double travel;
};

std::vector<Sample> sampleByTravel(const Trajectory& truth, double spacing) {
  std::vector<Sample> out;
  double travel = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (i > 0) travel += (truth[i].pose.translation() - truth[i - 1].pose.translation()).norm();
    if (out.empty() || travel - out.back().travel >= spacing) out.push_back({truth[i].utime, truth[i].pose.translation(), travel});
  }
  return out;
}

}  // namespace

LoopRecall loopRecall(const Trajectory& truth, const std::vector<JudgedLoop>& loops, const LoopRecallConfig& config) {
  LoopRecall out;
  for (const JudgedLoop& l : loops) (l.correct ? out.correct : out.wrong) += 1;
  out.accepted = static_cast<int>(loops.size());

  const std::vector<Sample> samples = sampleByTravel(truth, config.sample_spacing_m);
  const double r_sq = config.revisit_radius_m * config.revisit_radius_m;
  std::vector<bool> revisit(samples.size(), false);
  for (std::size_t i = 0; i < samples.size(); ++i)
    for (std::size_t j = 0; j < i && !revisit[i]; ++j)
      revisit[i] = samples[i].travel - samples[j].travel >= config.min_travel_m &&
                   static_cast<double>(samples[i].utime - samples[j].utime) * 1e-6 >= config.min_age_s &&
                   (samples[i].position - samples[j].position).squaredNorm() <= r_sq;

  // Each run of revisit samples spans from its first sample to the sample after its last one.
  for (std::size_t i = 0; i < samples.size();) {
    if (!revisit[i]) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < samples.size() && revisit[end]) ++end;
    const std::int64_t from = samples[i].utime;
    const std::int64_t to = end < samples.size() ? samples[end].utime : truth.back().utime + 1;
    ++out.revisits;
    const bool closed = std::any_of(loops.begin(), loops.end(), [&](const JudgedLoop& l) {
      return l.correct && l.query_utime >= from && l.query_utime < to;
    });
    if (closed) ++out.revisits_closed;
    i = end;
  }
  return out;
}

}  // namespace adit::eval
