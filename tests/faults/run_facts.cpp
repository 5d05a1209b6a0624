// fault-facts: what a fault test needs to know about a recorded live run, from its lcmlog(s) (a recorder's
// numbered series in order):
//   fault-facts [--out DIR] LOG [LOG ...]
// prints one line per fact, `key value`, for the test scripts to assert on:
//   messages <CHANNEL> N               messages recorded per channel
//   counter <STATUS_CHANNEL> <NAME> N  the newest value of each STATUS counter
//   status_gap_s <STATUS_CHANNEL> S    the longest wall-clock silence between two STATUS of a process after
//                                      its first one (a stalled process stops publishing STATUS)
//   inputs|outputs|drops|state <STATUS_CHANNEL> V   from the newest STATUS of the process
//   restarted <STATUS_CHANNEL> N       times the process's status counters went back (it restarted)
//   jump_m / jump_deg MAX              the largest difference between the estimated and the true motion of two
//                                      consecutive ODOM_MAPPED poses (matched to GROUND_TRUTH by utime)
//   jump_at_s T                        sensor seconds after the first pose where that largest difference is
// With --out, also writes DIR/mapped.tum (ODOM_MAPPED) and DIR/truth.tum (GROUND_TRUTH) for `adit eval`.
#include "eval/trajectory_io.hpp"
#include "msg/convert.hpp"
#include "runtime/lcm_log.hpp"

#include <adit/odometry_t.hpp>
#include <adit/status_t.hpp>
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace {

struct StatusFacts {
  std::map<std::string, std::int64_t> counters;
  std::int64_t last_stamp = -1, longest_gap_us = 0, prev_inputs = -1, outputs = 0, drops = 0;
  std::string state;
  int restarted = 0;
};

template <typename M>
bool decode(const std::vector<std::uint8_t>& data, M& m) {
  return m.decode(data.data(), 0, static_cast<int>(data.size())) >= 0;
}

// Largest |estimated motion - true motion| between consecutive estimated poses that both have a true pose.
void printJump(const adit::Trajectory& est, const adit::Trajectory& truth) {
  std::map<std::int64_t, Eigen::Isometry3d> gt;
  for (const auto& p : truth) gt[p.utime] = p.pose;
  double worst_m = 0, worst_deg = 0, worst_at = 0;
  for (std::size_t i = 1; i < est.size(); ++i) {
    const auto a = gt.find(est[i - 1].utime), b = gt.find(est[i].utime);
    if (a == gt.end() || b == gt.end()) continue;
    const Eigen::Isometry3d d_est = est[i - 1].pose.inverse() * est[i].pose;
    const Eigen::Isometry3d d_true = a->second.inverse() * b->second;
    const Eigen::Isometry3d err = d_true.inverse() * d_est;
    const double m = err.translation().norm();
    const double deg = Eigen::AngleAxisd(err.rotation()).angle() * 180.0 / M_PI;
    if (m > worst_m) worst_at = static_cast<double>(est[i].utime - est.front().utime) * 1e-6;
    worst_m = std::max(worst_m, m);
    worst_deg = std::max(worst_deg, deg);
  }
  fmt::print("jump_m {:.4f}\njump_deg {:.4f}\njump_at_s {:.1f}\n", worst_m, worst_deg, worst_at);
}

}  // namespace

int main(int argc, char** argv) {
  std::string out_dir;
  std::vector<std::string> logs;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--out" && i + 1 < argc) out_dir = argv[++i];
    else logs.push_back(a);
  }
  if (logs.empty()) {
    std::fprintf(stderr, "usage: fault-facts [--out DIR] LOG [LOG ...]\n");
    return 2;
  }
  std::map<std::string, std::int64_t> messages;
  std::map<std::string, StatusFacts> status;
  adit::Trajectory mapped, truth;
  for (const auto& log : logs) {
    adit::runtime::LogReader reader(log);
    adit::runtime::LogEvent e;
    while (reader.next(e)) {
      ++messages[e.channel];
      if (e.channel.rfind("STATUS_", 0) == 0) {
        adit::status_t s;
        if (!decode(e.data, s)) continue;
        StatusFacts& f = status[e.channel];
        if (f.last_stamp >= 0) f.longest_gap_us = std::max(f.longest_gap_us, e.timestamp - f.last_stamp);
        f.last_stamp = e.timestamp;
        if (s.inputs < f.prev_inputs) ++f.restarted;
        f.prev_inputs = s.inputs;
        f.outputs = s.outputs;
        f.drops = s.drops;
        f.state = s.state;
        for (int k = 0; k < s.num_counters; ++k) f.counters[s.counter_names[k]] = s.counter_values[k];
      } else if (e.channel == "ODOM_MAPPED" || e.channel == "GROUND_TRUTH") {
        adit::odometry_t m;
        if (!decode(e.data, m)) continue;
        const adit::PoseEstimate p = adit::msg::fromMessage(m);
        (e.channel == "ODOM_MAPPED" ? mapped : truth).push_back({p.utime, p.pose});
      }
    }
  }
  for (const auto& [channel, n] : messages) fmt::print("messages {} {}\n", channel, n);
  for (const auto& [channel, f] : status) {
    for (const auto& [name, v] : f.counters) fmt::print("counter {} {} {}\n", channel, name, v);
    fmt::print("inputs {} {}\noutputs {} {}\ndrops {} {}\nstate {} {}\n", channel, f.prev_inputs, channel, f.outputs,
               channel, f.drops, channel, f.state);
    fmt::print("status_gap_s {} {:.2f}\nrestarted {} {}\n", channel, static_cast<double>(f.longest_gap_us) * 1e-6,
               channel, f.restarted);
  }
  printJump(mapped, truth);
  if (!out_dir.empty()) {
    adit::eval::writeTum(out_dir + "/mapped.tum", mapped);
    adit::eval::writeTum(out_dir + "/truth.tum", truth);
  }
  return 0;
}
