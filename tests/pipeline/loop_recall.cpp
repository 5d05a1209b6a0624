// Loop closure's precision and recall on simulated drives (issue 16's table): the whole pipeline of
// `adit replay` on the simulator, each accepted loop judged against the truth (false beyond 1 m / 5 deg),
// each pass through a mapped place counted as one revisit (eval/loop_recall.hpp; within 3 m, farther back
// than the loop closer's own exclusion of recent keyframes and seconds). Prints one markdown row per drive.
//   loop_recall WORLD SECONDS SEED [SEED ...]
#include "sim_pipeline.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>
#include <string>

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s WORLD SECONDS SEED [SEED ...]\n", argv[0]);
    return 2;
  }
  const std::string world = argv[1];
  const double seconds = std::atof(argv[2]);
  const adit::Config config = adit::runtime::loadConfig({std::string(ADIT_SOURCE_DIR) + "/launch/config/pipeline.yaml"});
  adit::eval::LoopRecallConfig recall;
  recall.min_travel_m = config.get<double>("loop.exclude_recent_keyframes", 50.0) * config.get<double>("loop.keyframe_distance", 1.0);
  recall.min_age_s = config.get<double>("loop.exclude_recent_seconds", 30.0);
  for (int i = 3; i < argc; ++i) {
    const auto seed = static_cast<std::uint64_t>(std::atoll(argv[i]));
    const auto run = adit::test::runSimPipeline(world, seconds, seed);
    const auto r = adit::eval::loopRecall(run.ground_truth, run.judged_loops, recall);
    const auto ratio = [](int n, double value) { return n > 0 ? fmt::format("{:.2f}", value) : std::string("-"); };
    fmt::print("| {} | {:.0f} | {} | {} | {} | {} | {} | {} of {} | {} |\n", world, seconds, seed, r.accepted, r.correct,
               r.wrong, ratio(r.accepted, r.precision()), r.revisits_closed, r.revisits, ratio(r.revisits, r.recall()));
    std::fflush(stdout);
  }
  return 0;
}
