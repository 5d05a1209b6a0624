// Loop closure's precision and recall on simulated drives (issue 16's table): the whole pipeline of
// `adit replay` on the simulator, each accepted loop judged against the truth (false beyond 1 m / 5 deg),
// each pass through a mapped place counted as one revisit (eval/loop_recall.hpp; within 3 m, farther back
// than the loop closer's own exclusion of recent keyframes and seconds). Prints one markdown row per drive.
//   loop_recall [--set KEY=VALUE ...] WORLD SECONDS SEED [SEED ...]
// --set changes a pipeline key for the drives (e.g. --set loop.keypoints.use=false for the table without LinK3D).
#include "sim_pipeline.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

int main(int argc, char** argv) {
  std::vector<std::pair<std::string, std::string>> overrides;
  int first = 1;
  while (first + 1 < argc && std::string(argv[first]) == "--set") {
    const std::string kv = argv[first + 1];
    const auto eq = kv.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "--set needs KEY=VALUE, got '%s'\n", kv.c_str());
      return 2;
    }
    overrides.emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
    first += 2;
  }
  if (argc - first < 3) {
    std::fprintf(stderr, "usage: %s [--set KEY=VALUE ...] WORLD SECONDS SEED [SEED ...]\n", argv[0]);
    return 2;
  }
  const std::string world = argv[first];
  const double seconds = std::atof(argv[first + 1]);
  adit::Config config = adit::runtime::loadConfig({std::string(ADIT_SOURCE_DIR) + "/launch/config/pipeline.yaml"});
  for (const auto& [key, value] : overrides) config.set(key, value);
  adit::test::SimPipelineSetup setup;
  setup.configure = [&overrides](adit::Config& c) {
    for (const auto& [key, value] : overrides) c.set(key, value);
  };
  adit::eval::LoopRecallConfig recall;
  recall.min_travel_m = config.get<double>("loop.exclude_recent_keyframes", 50.0) * config.get<double>("loop.keyframe_distance", 1.0);
  recall.min_age_s = config.get<double>("loop.exclude_recent_seconds", 30.0);
  for (int i = first + 2; i < argc; ++i) {
    const auto seed = static_cast<std::uint64_t>(std::atoll(argv[i]));
    const auto run = adit::test::runSimPipeline(world, seconds, seed, setup);
    const auto r = adit::eval::loopRecall(run.ground_truth, run.judged_loops, recall);
    const auto ratio = [](int n, double value) { return n > 0 ? fmt::format("{:.2f}", value) : std::string("-"); };
    fmt::print("| {} | {:.0f} | {} | {} | {} | {} | {} | {} of {} | {} |\n", world, seconds, seed, r.accepted, r.correct,
               r.wrong, ratio(r.accepted, r.precision()), r.revisits_closed, r.revisits, ratio(r.revisits, r.recall()));
    std::fflush(stdout);
    const auto counter = [&run](const char* name) {
      const auto it = run.loop_counters.find(name);
      return it == run.loop_counters.end() ? std::int64_t{0} : it->second;
    };
    fmt::print(stderr, "{} {} s seed {}: candidates {}, rejected fitness {} degenerate {} odometry {} pairwise {}; "
               "LinK3D seeds {}, fits found only from them {}, refused as ambiguous {}; contested {}\n", world, seconds, seed,
               counter("loop_candidates"), counter("rejected_fitness"), counter("rejected_degenerate"),
               counter("rejected_odometry_gate"), counter("rejected_pairwise"), counter("keypoint_seeds"),
               counter("keypoint_loops"), counter("rejected_ambiguous"), counter("contested"));
  }
  return 0;
}
