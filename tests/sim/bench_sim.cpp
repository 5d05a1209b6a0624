// Simulator speed. The headline figure is the counter `sim_s_per_cpu_s` of BM_SimulateStream: simulated seconds
// (all sweeps + IMU samples) produced per second of one core (CPU time of the benchmark thread, so other jobs on
// a shared machine do not distort it). `sim_s_per_wall_s` is the same against the wall clock; on an idle core
// the two agree. Target: >= 20 for vlp16.
#include "sim/simulator.hpp"

#include <benchmark/benchmark.h>

#include <chrono>

namespace {

using adit::sim::SimConfig;
using adit::sim::SimEvent;
using adit::sim::Simulator;

const char* kWorlds[] = {"roadway-loop", "roadway-straight", "room-and-pillar", "featureless"};
const char* kSensors[] = {"vlp16", "rs16", "hdl64"};

// Full event stream (sweeps + 200 Hz IMU) over 20 s of driving, world built outside the timing.
void BM_SimulateStream(benchmark::State& state) {
  SimConfig config;
  config.world = kWorlds[state.range(0)];
  config.sensor = kSensors[state.range(1)];
  config.duration_s = 20.0;
  const Simulator prototype(config);  // warms nothing; each iteration gets a fresh stream below
  double simulated = 0.0, wall = 0.0;
  std::int64_t points = 0;
  for (auto _ : state) {
    state.PauseTiming();
    Simulator sim(config);
    state.ResumeTiming();
    const auto start = std::chrono::steady_clock::now();
    SimEvent ev;
    while (sim.next(ev))
      if (ev.kind == SimEvent::Kind::Scan) points += static_cast<std::int64_t>(ev.scan.points.size());
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    simulated += config.duration_s;
  }
  state.counters["sim_s_per_cpu_s"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
  state.counters["sim_s_per_wall_s"] = simulated / wall;
  state.counters["points_per_s"] = benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsRate);
  state.SetLabel(std::string(config.world) + "/" + config.sensor);
  benchmark::DoNotOptimize(prototype.numSweeps());
}
BENCHMARK(BM_SimulateStream)
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({2, 0})
    ->Args({3, 0})
    ->Args({0, 1})
    ->Args({0, 2})
    ->Unit(benchmark::kMillisecond);  // rates per CPU second of this thread: "on one core", whatever the load

// World construction (geometry + BVH) and motion planning for a 500 s run.
void BM_BuildSimulator(benchmark::State& state) {
  SimConfig config;
  config.world = kWorlds[state.range(0)];
  config.duration_s = 500.0;
  for (auto _ : state) {
    Simulator sim(config);
    benchmark::DoNotOptimize(sim.world().scene.size());
  }
  state.SetLabel(config.world);
}
BENCHMARK(BM_BuildSimulator)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
