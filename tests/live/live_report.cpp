// live_report <record.lcmlog> [--tum CHANNEL out.tum] [--sensors out.lcmlog]: what the live-run scripts
// check in a recording.
//   restart <process> first_output_after_s=<uptime at its first STATUS with outputs> <recovered counters>
//   map_update messages=<n> bytes=<n> span_s=<s> kB_per_s=<rate>
//   counters <process> <name>=<value> ...   (each process's last STATUS: what it counted over the run)
//   latency LIDAR_POINTS->ODOM_MAPPED n=<sweeps> p50_ms= p99_ms= max_ms=
// The latency is measured by the recorder: the wall-clock receive times lcm-logger wrote for a sweep's
// LIDAR_POINTS and for the ODOM_MAPPED of the same sensor time (every stage on the path included).
// With --tum, the odometry_t poses on CHANNEL are written as TUM (e.g. ODOM_MAPPED, for adit eval); with
// --sensors, the LIDAR_POINTS, IMU and GROUND_TRUTH events are copied to a log `adit replay` can run.
#include "eval/trajectory_io.hpp"
#include "msg/convert.hpp"
#include "runtime/lcm_log.hpp"

#include <adit/lidar_scan_t.hpp>
#include <adit/map_update_t.hpp>
#include <adit/odometry_t.hpp>
#include <adit/point_cloud_t.hpp>
#include <adit/status_t.hpp>

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  std::string tum_channel, tum_path, sensors_path;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--tum" && i + 2 < argc) {
      tum_channel = argv[++i];
      tum_path = argv[++i];
    } else if (a == "--sensors" && i + 1 < argc) {
      sensors_path = argv[++i];
    } else {
      argc = 0;
    }
  }
  if (argc < 2) {
    std::fprintf(stderr, "usage: live_report <record.lcmlog> [--tum CHANNEL out.tum] [--sensors out.lcmlog]\n");
    return 2;
  }
  std::unique_ptr<adit::runtime::LogWriter> sensors;
  if (!sensors_path.empty()) sensors = std::make_unique<adit::runtime::LogWriter>(sensors_path);
  adit::Trajectory poses;
  std::set<std::string> reported;
  std::map<std::string, adit::status_t> last_status;
  std::map<std::int64_t, std::int64_t> sweep_received;  // sensor utime -> recorder's receive time (us)
  std::vector<double> latency_ms;
  std::int64_t update_bytes = 0, updates = 0, first_update = -1, last_update = -1;
  adit::runtime::LogReader log(argv[1]);
  adit::runtime::LogEvent e;
  while (log.next(e)) {
    const auto* data = e.data.data();
    const int size = static_cast<int>(e.data.size());
    if (sensors && (e.channel == "LIDAR_POINTS" || e.channel == "IMU" || e.channel == "GROUND_TRUTH"))
      sensors->write(e.channel, e.data.data(), e.data.size(), e.timestamp);
    if (e.channel.rfind("STATUS_", 0) == 0) {
      adit::status_t s;
      if (s.decode(data, 0, size) < 0) continue;
      last_status[s.process] = s;
      if (reported.count(s.process) || s.outputs == 0) continue;
      std::map<std::string, std::int64_t> counters;
      for (int i = 0; i < s.num_counters; ++i) counters[s.counter_names[i]] = s.counter_values[i];
      if (!counters.count("restarted")) continue;
      reported.insert(s.process);
      std::printf("restart %s first_output_after_s=%.1f", s.process.c_str(), s.uptime_s);
      for (const auto& [name, value] : counters)
        if (name.rfind("recovered", 0) == 0 || name == "checkpoint_refused")
          std::printf(" %s=%lld", name.c_str(), static_cast<long long>(value));
      std::printf("\n");
    } else if (e.channel == "MAP_UPDATE") {
      ++updates;
      update_bytes += size;
      if (first_update < 0) first_update = e.timestamp;
      last_update = e.timestamp;
    }
    if (e.channel == "LIDAR_POINTS") {
      adit::lidar_scan_t compact;
      adit::point_cloud_t full;
      if (compact.decode(data, 0, size) >= 0) sweep_received[compact.header.utime] = e.timestamp;
      else if (full.decode(data, 0, size) >= 0) sweep_received[full.header.utime] = e.timestamp;
    } else if (e.channel == "ODOM_MAPPED") {
      adit::odometry_t m;
      if (m.decode(data, 0, size) >= 0) {
        const auto it = sweep_received.find(m.header.utime);
        if (it != sweep_received.end()) latency_ms.push_back((e.timestamp - it->second) * 1e-3);
      }
    }
    if (e.channel == tum_channel) {
      adit::odometry_t m;
      if (m.decode(data, 0, size) < 0) continue;
      const adit::PoseEstimate p = adit::msg::fromMessage(m);
      poses.push_back({p.utime, p.pose});
    }
  }
  const double span = last_update > first_update ? (last_update - first_update) * 1e-6 : 0.0;
  std::printf("map_update messages=%lld bytes=%lld span_s=%.1f kB_per_s=%.1f\n", static_cast<long long>(updates),
              static_cast<long long>(update_bytes), span, span > 0 ? update_bytes / span / 1000.0 : 0.0);
  if (!latency_ms.empty()) {
    std::sort(latency_ms.begin(), latency_ms.end());
    const auto at = [&](double q) { return latency_ms[static_cast<std::size_t>(q * (latency_ms.size() - 1))]; };
    std::printf("latency LIDAR_POINTS->ODOM_MAPPED n=%zu p50_ms=%.1f p99_ms=%.1f max_ms=%.1f\n", latency_ms.size(),
                at(0.5), at(0.99), latency_ms.back());
  }
  for (const auto& [process, s] : last_status) {
    std::printf("counters %s", process.c_str());
    for (int i = 0; i < s.num_counters; ++i)
      std::printf(" %s=%lld", s.counter_names[i].c_str(), static_cast<long long>(s.counter_values[i]));
    std::printf("\n");
  }
  if (!tum_channel.empty()) adit::eval::writeTum(tum_path, poses);
  if (sensors) sensors->close();
  return 0;
}
