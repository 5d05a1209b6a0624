// Mutation campaign per channel: real messages of every channel a pipeline node receives (recorded_run.hpp),
// mutated deterministically from a seed (mutator.hpp), each delivered through Node::deliver to a live node
// that keeps receiving the run's valid messages in between. Asserts, per channel: no crash (nor a sanitizer
// finding in a sanitized build), every malformed message (truncated, wrong fingerprint) refused and counted
// when it arrives, every output of the node finite and valid, the node's outputs continuing after the
// mutations (the clean last quarter of the run gives as many outputs as without them) and, for the nodes
// that estimate poses, the pose after the mutations within a bound of the run without them. Prints the
// table of the README's Reliability section.
//
//   mutation_campaign [--count N] [--seed S] [--seconds T] [--only CHANNEL] [--ops MASK]
// MASK: bit i enables mutation kind i of mutator.hpp's Op (default: all).
#include "field_map.hpp"
#include "mutator.hpp"
#include "recorded_run.hpp"

#include "msg/encode.hpp"
#include "msg/validate.hpp"
#include "nodes/registry.hpp"
#include "runtime/process.hpp"

#include <adit/features_t.hpp>
#include <adit/odometry_t.hpp>
#include <adit/pose_graph_t.hpp>
#include <adit/command_t.hpp>
#include <adit/imu_t.hpp>
#include <adit/lidar_scan_t.hpp>
#include <adit/point_cloud_t.hpp>

#include <Eigen/Geometry>
#include <spdlog/spdlog.h>
#include <algorithm>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <utility>
#include <memory>
#include <string>
#include <vector>

namespace adit::mutation {
namespace {

namespace fs = std::filesystem;
using runtime::Bytes;

struct Target {
  std::string node;       // pipeline node name
  std::string channel;    // input channel mutated
  std::string label;      // row name
  int type_index;         // wire type of the channel's messages
  bool full_sweeps = false;  // LIDAR_POINTS as point_cloud_t
  std::string pose_channel;  // output carrying the node's pose estimate ("" = none)
  double pose_bound_m = 0;
  // A single forged stamp ahead is held and dropped (runtime/node.cpp, max_step_periods), but this pass puts
  // several copies into one gap, and consistent forged stamps in a row look like a real jump of the sensor's
  // time (only authentication would tell): stamp mutations of this channel run as a separate pass whose pose is
  // reported, not asserted.
  bool stamps_known_to_move_pose = false;
  bool in_prior_map = false;  // the node runs with the recorded run's own map bundle (reloc.prior_map)
};

template <class Msg>
int typeOf() { return msg::wire::TypeIndex<Msg>::value; }

// Bound on how far the pose of the clean last quarter may differ from the run fed the unmutated copies. The
// odometry integrates: a mutated sweep it uses (points moved by a flipped bit) is registered like any other
// and its error stays in the trajectory; the mapper re-registers against its map. 0.5 m is a tenth of a
// roadway's width (4-5 m): a map drawn from poses that far apart still shows one roadway, not two.
std::vector<Target> targets() {
  return {
      {"feature", "LIDAR_POINTS", "LIDAR_POINTS (lidar_scan_t, compact)", typeOf<adit::lidar_scan_t>(), false, "", 0},
      {"feature", "LIDAR_POINTS", "LIDAR_POINTS (point_cloud_t, full)", typeOf<adit::point_cloud_t>(), true, "", 0},
      {"feature", "IMU", "IMU (feature)", typeOf<adit::imu_t>(), false, "", 0},
      {"feature", "ODOM_SCAN", "ODOM_SCAN (feature: deskew prior)", typeOf<adit::odometry_t>(), false, "", 0},
      {"odometry", "FEATURES", "FEATURES", typeOf<adit::features_t>(), false, "ODOM_SCAN", 0.5, true},
      {"odometry", "IMU", "IMU (odometry)", typeOf<adit::imu_t>(), false, "ODOM_SCAN", 0.5},
      {"mapper", "ODOM_SCAN", "ODOM_SCAN (mapper)", typeOf<adit::odometry_t>(), false, "ODOM_MAPPED", 0.5},
      {"mapper", "POSE_GRAPH", "POSE_GRAPH", typeOf<adit::pose_graph_t>(), false, "ODOM_MAPPED", 0.5},
      {"loop_closer", "ODOM_MAPPED", "ODOM_MAPPED", typeOf<adit::odometry_t>(), false, "", 0},
      {"loop_closer", "FEATURES", "FEATURES (loop closer: LinK3D keypoints)", typeOf<adit::features_t>(), false, "", 0},
      {"loop_closer", "MAPPER_COMMAND", "MAPPER_COMMAND", typeOf<adit::command_t>(), false, "", 0},
      // Relocalising in a saved map: the mapped poses it tracks and the operator's pose guesses. Its pose in
      // the map after the mutations: within the same bound (a fix refused is re-queried, never guessed).
      {"relocaliser", "ODOM_MAPPED", "ODOM_MAPPED (relocaliser)", typeOf<adit::odometry_t>(), false, "POSE_IN_MAP", 0.5,
       false, true},
      {"relocaliser", "RELOC_COMMAND", "RELOC_COMMAND", typeOf<adit::command_t>(), false, "POSE_IN_MAP", 0.5, false, true},
  };
}

// Every output the node publishes: decoded and value-checked as its receivers would.
struct Outputs : runtime::Sink {
  void publish(const std::string& channel, const Bytes& data, std::int64_t utime) override {
    ++count;
    if (utime >= tail_from) ++tail;
    std::string bad;
    if (channel == "FEATURES") bad = check<adit::features_t>(data);
    if (channel == "ODOM_SCAN" || channel == "ODOM_MAPPED" || channel == "POSE_IN_MAP") {
      bad = check<adit::odometry_t>(data);
      adit::odometry_t m;
      if (bad.empty() && m.decode(data.data(), 0, static_cast<int>(data.size())) > 0 && channel == pose_channel)
        poses[utime] = Eigen::Vector3d(m.position[0], m.position[1], m.position[2]);
    }
    if (channel == "POSE_GRAPH") bad = check<adit::pose_graph_t>(data);
    if (!bad.empty()) invalid.push_back(channel + ": " + bad);
  }
  template <class Msg>
  static std::string check(const Bytes& data) {
    Msg m;
    if (m.decode(data.data(), 0, static_cast<int>(data.size())) < 0) return "undecodable";
    const msg::Validation v = msg::validate(m, msg::InputLimits{});
    return v ? v->counter + ": " + v->reason : "";
  }
  std::int64_t tail_from = INT64_MAX;
  std::string pose_channel;
  std::int64_t count = 0, tail = 0;
  std::map<std::int64_t, Eigen::Vector3d> poses;
  std::vector<std::string> invalid;
};

void setHeader(Bytes& b, int type_index, std::int64_t utime, std::int64_t seq) {
  for (const Field& f : mapFields(type_index, b.data(), b.size())) {
    if (f.depth != 1 || f.kind != msg::wire::Kind::Int64) continue;
    const std::int64_t v = f.name == "utime" ? utime : f.name == "seq" ? seq : 0;
    if (f.name != "utime" && f.name != "seq") continue;
    for (int i = 0; i < 8; ++i) b[f.offset + 7 - static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(v) >> (8 * i));
    if (f.name == "seq") return;  // header: utime, then seq
  }
}

struct Row {
  std::string label;
  int tried = 0, refused = 0;
  std::map<std::string, std::int64_t> refused_by;  // counter -> mutations refused under it when delivered
  int flagged = 0;                                  // used, with an anomaly counted (seq gap, time jump)
  std::map<std::string, std::int64_t> flagged_by;
  int stage_exceptions = 0;
  std::map<std::string, std::int64_t> later;       // counters raised while delivering the valid messages
  std::map<Op, std::pair<int, int>> by_kind;     // kind -> (tried, refused)
  std::int64_t tail_outputs = 0, reference_tail_outputs = 0;
  double pose_deviation_m = -1;  // max over the clean tail; -1 = no pose output
  double seconds = 0;
  std::vector<std::string> failures;
};

class Campaign {
 public:
  // map_run: the recording of the targets that relocalise in a saved map (in_prior_map), in its own bundle.
  Campaign(const Config& config, const RecordedRun& run, const RecordedRun& map_run, std::uint64_t seed, int count,
           unsigned ops)
      : config_(config), map_config_(config), run_(run), map_run_(map_run), seed_(seed), count_(count), ops_(ops) {
    map_config_.set("reloc.prior_map", map_run.bundle_dir);
    std::vector<std::uint64_t> hashes;
    for (int i = 0; i < msg::wire::kNumStructs; ++i) hashes.push_back(msg::wireHash(i));
    hashes_ = hashes;
    spdlog::set_level(spdlog::level::off);  // one line per refused message: thousands
  }

  // The kinds of mutation (bit i = Op i) and how many per channel for the next run().
  void configure(unsigned ops, int count) { ops_ = ops; count_ = count; }

  Row run(const Target& t) {
    const auto started = std::chrono::steady_clock::now();
    Row row;
    row.label = t.label;
    const std::vector<Event> stream = streamOf(t);
    std::vector<std::size_t> target_positions;
    for (std::size_t i = 0; i < stream.size(); ++i)
      if (stream[i].channel == t.channel) target_positions.push_back(i);
    if (target_positions.size() < 4) {
      row.failures.push_back("fewer than 4 recorded messages on " + t.channel);
      return row;
    }
    // Mutations go between the valid messages of the first three quarters; the last quarter stays clean.
    const std::size_t zone = target_positions.size() * 3 / 4;
    const std::int64_t tail_from = stream[target_positions[zone]].utime;
    const std::size_t per_gap = static_cast<std::size_t>(count_ + static_cast<int>(zone) - 2) / (zone - 1);

    // The mutated run first; then the reference: the same stream with, in place of each mutation the node
    // used, the unmutated copy it was made from. The poses differ only by what the mutations changed.
    Outputs outputs;
    outputs.tail_from = tail_from;
    outputs.pose_channel = t.pose_channel;
    std::set<std::pair<std::size_t, std::size_t>> used;  // (stream index, copy) of mutations not refused
    play(t, stream, target_positions, zone, per_gap, &row, used, outputs);
    Outputs reference;
    reference.tail_from = tail_from;
    reference.pose_channel = t.pose_channel;
    play(t, stream, target_positions, zone, per_gap, nullptr, used, reference);

    row.tail_outputs = outputs.tail;
    row.reference_tail_outputs = reference.tail;
    for (const std::string& bad : outputs.invalid) row.failures.push_back("invalid output " + bad);
    if (outputs.tail < reference.tail)
      row.failures.push_back("outputs stopped: " + std::to_string(outputs.tail) + " in the clean tail, " +
                             std::to_string(reference.tail) + " without mutations");
    if (!t.pose_channel.empty()) {
      row.pose_deviation_m = 0;
      int compared = 0;
      for (const auto& [utime, p] : reference.poses) {
        if (utime < tail_from) continue;
        const auto it = outputs.poses.find(utime);
        if (it == outputs.poses.end()) continue;
        row.pose_deviation_m = std::max(row.pose_deviation_m, (it->second - p).norm());
        ++compared;
      }
      if (compared == 0) row.failures.push_back("no pose of the clean tail to compare");
      if (!(row.pose_deviation_m <= t.pose_bound_m))
        row.failures.push_back("pose moved by " + std::to_string(row.pose_deviation_m) + " m (bound " +
                               std::to_string(t.pose_bound_m) + " m)");
    }
    row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return row;
  }

  // Delivers the stream with `per_gap` copies before each target message of the first `zone`: mutated (and
  // scored in *row, the used ones noted) when row is given, else only the used ones, unmutated.
  void play(const Target& t, const std::vector<Event>& stream, const std::vector<std::size_t>& target_positions,
            std::size_t zone, std::size_t per_gap, Row* row, std::set<std::pair<std::size_t, std::size_t>>& used,
            Outputs& outputs) {
    const fs::path dir = folder(t, row ? "mut" : "ref");
    auto node = makeNode(t, dir);
    Mutator mutator(seed_ ^ std::hash<std::string>{}(t.label), hashes_, ops_);
    std::size_t next_target = 1;  // index into target_positions: copies go just before it
    std::int64_t prev_utime = -1, prev_seq = -1;
    int tried = 0;
    for (std::size_t i = 0; i < stream.size(); ++i) {
      const Event& e = stream[i];
      if (next_target < zone && i == target_positions[next_target]) {
        for (std::size_t k = 0; k < per_gap && tried < count_; ++k, ++tried) {
          // A copy of this valid message, stamped between the previous one and it (so that the valid message
          // still continues its stream), its seq repeating the previous one's; then one mutation.
          Bytes base = e.bytes;
          const std::int64_t utime = prev_utime + (e.utime - prev_utime) * static_cast<std::int64_t>(k + 1) /
                                                      static_cast<std::int64_t>(per_gap + 1);
          setHeader(base, t.type_index, utime, prev_seq);
          const Mutation m = mutator.mutate(base, t.type_index);
          if (!row) {
            if (used.count({i, k})) node->deliver(t.channel, base.data(), base.size(), outputs);
            continue;
          }
          const runtime::Health before = node->health();
          node->deliver(t.channel, m.bytes.data(), m.bytes.size(), outputs);
          score(*row, m, base, before, node->health());
          if (!raised(before, node->health()).second) used.insert({i, k});
        }
        ++next_target;
      }
      const runtime::Health before = node->health();
      node->deliver(e.channel, e.bytes.data(), e.bytes.size(), outputs);
      if (row)
        for (const auto& [name, value] : node->health().counters) {
          if (!refusal(name) && !anomaly(name)) continue;
          const auto it = before.counters.find(name);
          const std::int64_t was = it == before.counters.end() ? 0 : it->second;
          if (value > was) row->later[name] += value - was;
        }
      if (e.channel == t.channel) {
        prev_utime = e.utime;
        prev_seq = seqOf(e, t.type_index);
      }
    }
    node->finish(outputs);
    fs::remove_all(dir);
  }

  static void score(Row& row, const Mutation& m, const Bytes& base, const runtime::Health& before,
                    const runtime::Health& after) {
    ++row.tried;
    ++row.by_kind[m.op].first;
    const auto [counter, refused] = raised(before, after);
    if (refused) {
      ++row.refused;
      ++row.refused_by[counter];
      ++row.by_kind[m.op].second;
      if (counter.find("stage_exception") != std::string::npos) ++row.stage_exceptions;
    } else if (!counter.empty()) {
      ++row.flagged;
      ++row.flagged_by[counter];
    } else if ((m.op == Op::Truncate || m.op == Op::Fingerprint) && !sameType(m.bytes, base)) {
      row.failures.push_back(std::string(kindName(m.op)) + ": used without a counter");
    }
  }

 private:
  std::vector<Event> streamOf(const Target& t) const {
    const auto probe = nodes::makeNode(t.node, configOf(t));
    std::vector<Event> stream;
    std::size_t sweep = 0;
    const RecordedRun& run = t.in_prior_map ? map_run_ : run_;
    for (const Event& e : run.events) {
      if (!probe->isInput(e.channel)) continue;
      if (e.channel == "LIDAR_POINTS" && t.full_sweeps) {
        stream.push_back(run.full_sweeps.at(sweep++));
        continue;
      }
      stream.push_back(e);
    }
    return stream;
  }

  std::unique_ptr<runtime::Node> makeNode(const Target& t, const fs::path& dir) const {
    auto node = nodes::makeNode(t.node, configOf(t));
    runtime::RunFolder f;
    f.dir = dir.string();
    f.run_id = "mutation";
    node->useRunFolder(f);
    return node;
  }

  fs::path folder(const Target& t, const std::string& tag) const {
    const fs::path dir = fs::temp_directory_path() /
                         ("adit_mutation_" + std::to_string(::getpid()) + "_" + t.node + "_" + t.channel + "_" + tag);
    fs::create_directories(dir);
    return dir;
  }

  // Counters that mean "this message was not used" (each refused input raises exactly one of them) and those
  // that flag an anomaly of a message that was used (a sequence gap, a time jump); statistics are neither.
  static bool refusal(const std::string& name) {
    static const std::set<std::string> names = {"decode_error", "oversized_count", "unknown_format_version",
                                                "time_backwards", "time_future", "duplicate_time", "empty_scan",
                                                "command_refused", "unknown_command", "invalid_graph",
                                                "stage_exception"};
    return names.count(name) > 0 || name.rfind("invalid_", 0) == 0;
  }
  static bool anomaly(const std::string& name) {
    return name == "seq_reset" || name == "lost_input" || name == "time_jump" || name == "time_resync";
  }
  // The refusal counters raised (joined by '+'), else the anomaly counters, else "".
  static std::pair<std::string, bool> raised(const runtime::Health& before, const runtime::Health& after) {
    std::string refused, flagged;
    for (const auto& [name, value] : after.counters) {
      const auto it = before.counters.find(name);
      if (value <= (it == before.counters.end() ? 0 : it->second)) continue;
      if (refusal(name)) refused += (refused.empty() ? "" : "+") + name;
      if (anomaly(name)) flagged += (flagged.empty() ? "" : "+") + name;
    }
    return refused.empty() ? std::make_pair(flagged, false) : std::make_pair(refused, true);
  }

  static bool sameType(const Bytes& a, const Bytes& b) {
    return a.size() >= 8 && b.size() >= 8 && std::memcmp(a.data(), b.data(), 8) == 0 && a.size() == b.size();
  }

  static std::int64_t seqOf(const Event& e, int type_index) {
    for (const Field& f : mapFields(type_index, e.bytes.data(), e.bytes.size()))
      if (f.depth == 1 && f.name == "seq" && f.kind == msg::wire::Kind::Int64) {
        std::uint64_t v = 0;
        for (int i = 0; i < 8; ++i) v = (v << 8) | e.bytes[f.offset + static_cast<std::size_t>(i)];
        return static_cast<std::int64_t>(v);
      }
    return -1;
  }

  const Config& configOf(const Target& t) const { return t.in_prior_map ? map_config_ : config_; }

  const Config& config_;
  Config map_config_;  // config_ with the recorded run's bundle as reloc.prior_map
  const RecordedRun& run_;
  const RecordedRun& map_run_;
  std::uint64_t seed_;
  int count_;
  unsigned ops_;
  std::vector<std::uint64_t> hashes_;
};

std::string top(const std::map<std::string, std::int64_t>& counts) {
  std::vector<std::pair<std::int64_t, std::string>> v;
  for (const auto& [name, n] : counts) v.push_back({n, name});
  std::sort(v.rbegin(), v.rend());
  std::string s;
  for (const auto& [n, name] : v) s += (s.empty() ? "" : ", ") + name + " " + std::to_string(n);
  return s.empty() ? "-" : s;
}

}  // namespace
}  // namespace adit::mutation

int main(int argc, char** argv) {
  using namespace adit::mutation;
  int count = 300;
  std::uint64_t seed = 1;
  double seconds = 8.0;
  std::string only;
  unsigned ops = ~0u;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--count") count = std::stoi(argv[i + 1]);
    else if (a == "--seed") seed = std::stoull(argv[i + 1]);
    else if (a == "--seconds") seconds = std::stod(argv[i + 1]);
    else if (a == "--only") only = argv[i + 1];
    else if (a == "--ops") ops = static_cast<unsigned>(std::stoul(argv[i + 1], nullptr, 0));
    else { std::fprintf(stderr, "usage: %s [--count N] [--seed S] [--seconds T] [--only CHANNEL] [--ops MASK]\n", argv[0]); return 2; }
  }
  const std::string launch = std::string(ADIT_SOURCE_DIR) + "/launch";
  const adit::Config config =
      adit::runtime::loadConfig({launch + "/config/pipeline.yaml", launch + "/sensors/sim.yaml"});
  const auto t0 = std::chrono::steady_clock::now();
  const RecordedRun run = recordRun(config, seconds, 4);
  std::printf("recorded %zu messages of %.0f s simulated in %.1f s; %d mutations per channel, seed %llu\n\n",
              run.events.size(), seconds, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
              count, static_cast<unsigned long long>(seed));
  // The relocaliser first fixes after ~8 s of this drive: its targets get a longer one, so that the clean last
  // quarter has poses in the map to compare (the pipeline targets keep the short run their bounds were set on).
  const RecordedRun map_run = recordRun(config, std::max(seconds, 12.0), 4);
  Campaign campaign(config, run, map_run, seed, count, ops);
  int failed = 0;
  std::printf("| channel (node) | tried | refused and counted, by counter | used, anomaly counted | used | counted while "
              "delivering the valid messages | clean-tail outputs (without mutations) | pose moved | result |\n");
  std::printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  std::vector<Row> rows;
  std::vector<std::pair<Target, std::pair<unsigned, int>>> passes;
  const unsigned stamps = 1u << static_cast<unsigned>(Op::Stamp);
  for (const Target& t : targets()) {
    if (!only.empty() && t.channel != only) continue;
    if (!t.stamps_known_to_move_pose || !(ops & stamps)) {
      passes.push_back({t, {ops, count}});
      continue;
    }
    passes.push_back({t, {ops & ~stamps, count}});
    Target known = t;
    known.label += ": stamps only (known defect, pose not asserted)";
    known.pose_bound_m = std::numeric_limits<double>::infinity();
    passes.push_back({known, {stamps, std::max(1, count / 5)}});
  }
  for (const auto& [t, setting] : passes) {
    campaign.configure(setting.first, setting.second);
    Row r = campaign.run(t);
    const std::string pose = r.pose_deviation_m < 0 ? "-" : std::to_string(r.pose_deviation_m).substr(0, 5) + " m";
    std::printf("| %s | %d | %d: %s | %d: %s | %d | %s | %lld (%lld) | %s | %s (%.1f s) |\n", r.label.c_str(), r.tried,
                r.refused, top(r.refused_by).c_str(), r.flagged, top(r.flagged_by).c_str(), r.tried - r.refused - r.flagged,
                top(r.later).c_str(),
                static_cast<long long>(r.tail_outputs), static_cast<long long>(r.reference_tail_outputs), pose.c_str(),
                (r.failures.empty() ? std::string("pass") : std::string("FAIL")).append(
                    r.stage_exceptions ? ", " + std::to_string(r.stage_exceptions) + " stage exceptions" : "").c_str(),
                r.seconds);
    std::fflush(stdout);
    rows.push_back(r);
  }
  std::printf("\nper mutation kind, all channels: tried / refused when delivered\n");
  std::map<Op, std::pair<int, int>> kinds;
  for (const Row& r : rows)
    for (const auto& [k, v] : r.by_kind) { kinds[k].first += v.first; kinds[k].second += v.second; }
  for (const auto& [k, v] : kinds) std::printf("  %-15s %6d / %6d\n", kindName(k), v.first, v.second);
  for (const Row& r : rows)
    for (std::size_t i = 0; i < r.failures.size() && i < 10; ++i, ++failed)
      std::printf("FAIL %s: %s\n", r.label.c_str(), r.failures[i].c_str());
  std::filesystem::remove_all(run.bundle_dir);
  std::filesystem::remove_all(map_run.bundle_dir);
  return failed ? 1 : 0;
}
