// adit info <log>: what an LCM log holds, per channel: message count, type, time span, rate, size per message
// and bandwidth (MB/s over the whole log's span, i.e. what the channel costs the bus and the disk), and the
// whole log's rate.
// adit info <file.bag>: a ROS 1 bag's topics, types, message counts, span and rate, and any lost chunk.
// adit info <bundle folder> [--keyframes FILE]: a map bundle's date, keyframes, extent, roadway length, sensor
// keys and files (every file's size and checksum are checked; a bad bundle is an error naming what is wrong);
// the keyframes' poses as TUM into FILE.
#include "commands.hpp"

#include "eval/trajectory_io.hpp"
#include "io/rosbag.hpp"
#include "map/map_bundle.hpp"
#include "msg/type_name.hpp"
#include "runtime/lcm_log.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

namespace {

struct ChannelStats {
  std::int64_t count = 0, bytes = 0, first = 0, last = 0;
  std::string type;
};

bool isRosbag(const std::string& path) {
  char magic[8] = {};
  std::ifstream(path, std::ios::binary).read(magic, sizeof(magic));
  return std::memcmp(magic, "#ROSBAG ", sizeof(magic)) == 0;
}

// Reads the whole bag (every chunk is decompressed: the counts are real, not the index's claims).
void printBagSummary(const std::string& path) {
  adit::io::BagReader reader(path);
  std::map<std::uint32_t, ChannelStats> per_conn;
  adit::io::BagMessage m;
  while (reader.next(m)) {
    ChannelStats& s = per_conn[m.conn];
    if (s.count++ == 0) s.first = m.time_ns;
    s.last = m.time_ns;
    s.bytes += static_cast<std::int64_t>(m.data.size());
  }
  fmt::print("{:<32} {:<28} {:>8} {:>10} {:>9} {:>10}\n", "topic", "type", "messages", "span_s", "rate_hz", "MB");
  for (const auto& [id, c] : reader.connections()) {
    const ChannelStats s = per_conn.count(id) ? per_conn.at(id) : ChannelStats{};
    const double span = static_cast<double>(s.last - s.first) * 1e-9;
    fmt::print("{:<32} {:<28} {:>8} {:>10.3f} {:>9.2f} {:>10.2f}\n", c.topic, c.type, s.count, span,
               span > 0 ? static_cast<double>(s.count - 1) / span : 0.0, static_cast<double>(s.bytes) / 1e6);
  }
  const adit::io::BagReadStats& st = reader.stats();
  fmt::print("{} chunks, {} messages\n", st.chunks, st.messages);
  if (st.chunks_lost || st.truncated || st.unknown_conn) {
    spdlog::error("bag '{}' is damaged: {} of {} chunk(s) lost, {} message(s) of undefined connections{}; last: {}", path,
                  st.chunks_lost, st.chunks, st.unknown_conn, st.truncated ? ", truncated" : "", st.last_error);
    throw CLI::RuntimeError(kExitDamagedInput);
  }
}

// keyframes_tum: also write the keyframes' poses (map frame) there as TUM, to plot or compare with a truth.
void printBundleSummary(const std::string& dir, const std::string& keyframes_tum) {
  adit::BundleSummary s;
  try {
    s = adit::readBundleSummary(dir);
    if (!keyframes_tum.empty()) {
      adit::Trajectory poses;
      for (const adit::BundleKeyframe& k : adit::loadMapBundle(dir).keyframes) poses.push_back({k.utime, k.pose});
      adit::eval::writeTum(keyframes_tum, poses);
    }
  } catch (const adit::BundleError& e) {
    spdlog::error("bad map bundle: {}", e.what());
    throw CLI::RuntimeError(kExitDamagedInput);
  }
  const Eigen::Vector3d size = s.extent_max - s.extent_min;
  fmt::print("map bundle {} (version {})\n", dir, s.version);
  fmt::print("  created        {} (sensor time of the newest keyframe)\n", s.created);
  fmt::print("  keyframes      {}\n", s.keyframes);
  fmt::print("  roadway        {:.1f} m (revisits counted once)\n", s.roadway_length_m);
  fmt::print("  extent         x {:.1f}..{:.1f}  y {:.1f}..{:.1f}  z {:.1f}..{:.1f} m ({:.1f} x {:.1f} x {:.1f} m)\n",
             s.extent_min.x(), s.extent_max.x(), s.extent_min.y(), s.extent_max.y(), s.extent_min.z(),
             s.extent_max.z(), size.x(), size.y(), size.z());
  fmt::print("  map voxel      {} m\n", s.map_voxel);
  for (const auto& [key, value] : s.sensor) fmt::print("  sensor         {} = {}\n", key, value);
  for (const auto& [name, f] : s.files)
    fmt::print("  file           {:<16} {:>12} bytes  crc32 {:08x}  ok\n", name, f.bytes, f.crc32);
}

}  // namespace

void registerInfoCommand(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  auto keyframes_tum = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("info", "Summarise an LCM log (messages, type, time span and rate per channel), a ROS 1 bag (topics, types, counts) or a map bundle");
  cmd->add_option("log", *path, "LCM log, ROS bag or map bundle folder")->required()->check(CLI::ExistingPath);
  cmd->add_option("--keyframes", *keyframes_tum, "Map bundle: also write its keyframes' poses (map frame) to this TUM file");
  cmd->callback([path, keyframes_tum] {
    if (std::filesystem::is_directory(*path)) return printBundleSummary(*path, *keyframes_tum);
    if (isRosbag(*path)) return printBagSummary(*path);
    adit::runtime::LogReader reader(*path);
    std::map<std::string, ChannelStats> channels;
    adit::runtime::LogEvent e;
    while (reader.next(e)) {
      ChannelStats& s = channels[e.channel];
      if (s.count++ == 0) {
        s.first = e.timestamp;
        s.type = adit::msg::messageTypeName(e.data.data(), e.data.size());
      }
      s.last = e.timestamp;
      s.bytes += static_cast<std::int64_t>(e.data.size());
    }
    if (channels.empty())
      throw std::runtime_error("'" + *path + "' holds no LCM event (empty, or not an LCM log)");
    // Bandwidth over the log's span (first to last event of any channel): a sparse channel's share of the run.
    std::int64_t first = 0, last = 0, total = 0;
    for (const auto& [name, s] : channels) {
      first = total == 0 ? s.first : std::min(first, s.first);
      last = std::max(last, s.last);
      total += s.bytes;
    }
    const double log_span = static_cast<double>(last - first) * 1e-6;
    const auto perSecond = [&](std::int64_t bytes) { return log_span > 0 ? static_cast<double>(bytes) / 1e6 / log_span : 0.0; };
    fmt::print("{:<24} {:>8} {:<16} {:>10} {:>9} {:>10} {:>10} {:>9}\n", "channel", "messages", "type", "span_s",
               "rate_hz", "MB", "kB/msg", "MB/s");
    for (const auto& [name, s] : channels) {
      const double span = static_cast<double>(s.last - s.first) * 1e-6;
      fmt::print("{:<24} {:>8} {:<16} {:>10.3f} {:>9.2f} {:>10.2f} {:>10.2f} {:>9.3f}\n", name, s.count,
                 s.type.empty() ? "?" : s.type, span, span > 0 ? static_cast<double>(s.count - 1) / span : 0.0,
                 static_cast<double>(s.bytes) / 1e6, static_cast<double>(s.bytes) / 1e3 / static_cast<double>(s.count),
                 perSecond(s.bytes));
    }
    fmt::print("{:<24} {:>8} {:<16} {:>10.3f} {:>9} {:>10.2f} {:>10} {:>9.3f}\n", "total", "", "", log_span, "",
               static_cast<double>(total) / 1e6, "", perSecond(total));
    if (reader.corruptFrames() || reader.truncated()) {
      spdlog::error("log '{}' is damaged: {} corrupt frame(s) skipped{}", *path, reader.corruptFrames(),
                    reader.truncated() ? ", truncated at the end" : "");
      throw CLI::RuntimeError(kExitDamagedInput);
    }
  });
}
