// Deterministic random numbers for the simulator.
//
// Why not <random>: std::normal_distribution and friends are implementation-defined, so the same seed may give
// different numbers with another standard library. The generator here is SplitMix64 (Steele, Lea, Flood 2014), a
// fixed, published algorithm that passes BigCrush, and the distributions are written out below, so a seed gives
// the same bits on every toolchain (only std::log/std::cos may differ in the last ulp between libm versions).
//
// Streams: every consumer (lidar noise of sweep k, IMU noise, world furniture, ...) derives its own generator
// from (seed, stream id), so changing one consumer never shifts the random numbers of another.
#pragma once

#include <cmath>
#include <cstdint>

namespace adit::sim {

// Mixes a 64-bit value into a well-distributed one (the SplitMix64 finaliser).
inline std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

// Stream ids of the simulator's independent random sources.
enum class Stream : std::uint64_t { World = 1, Motion = 2, Imu = 3, LidarSweep = 4, WorldCloud = 5, Wheel = 6 };

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(mix64(seed ^ 0x9E3779B97F4A7C15ULL)) {}
  // Generator for stream `stream`, item `index` (e.g. sweep number) of a run with seed `seed`.
  static Rng forStream(std::uint64_t seed, Stream stream, std::uint64_t index = 0) {
    return Rng(mix64(mix64(seed) ^ mix64(static_cast<std::uint64_t>(stream) * 0x632BE59BD9B4E019ULL + index)));
  }

  std::uint64_t next() {
    state_ += 0x9E3779B97F4A7C15ULL;
    return mix64(state_);
  }
  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next() >> 11) * (1.0 / 9007199254740992.0); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Uniform integer in [0, n) (n > 0); the modulo bias is below 1e-15 for the small n used here.
  int uniformInt(int n) { return static_cast<int>(next() % static_cast<std::uint64_t>(n)); }
  // Standard normal by Box-Muller; always consumes exactly two uniforms so streams stay aligned.
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }
  double normal(double mean, double sigma) { return mean + sigma * normal(); }

 private:
  std::uint64_t state_;
};

}  // namespace adit::sim
