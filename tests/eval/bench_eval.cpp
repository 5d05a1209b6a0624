// Cost of a full evaluation (association, Umeyama, APE, RPE 1/10/100 m, KITTI drift) per trajectory size.
#include "eval/evaluate.hpp"
#include "fixtures.hpp"

#include <benchmark/benchmark.h>

#include <random>

namespace {

void BM_Evaluate(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const adit::Trajectory gt = adit::eval::test::windingPath(n);
  adit::Trajectory est = gt;
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (adit::StampedPose& p : est) p.pose.translation() += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  for (auto _ : state) benchmark::DoNotOptimize(adit::eval::evaluate(gt, est));
  state.SetItemsProcessed(state.iterations() * n);
}
BENCHMARK(BM_Evaluate)->Arg(1000)->Arg(10000)->Arg(36000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
