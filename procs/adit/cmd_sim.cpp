// adit sim --world roadway-loop --sensor vlp16 --duration 180 --seed 1 -o run.lcmlog --gt run_gt.tum
#include "commands.hpp"

#include "eval/trajectory_io.hpp"
#include "io/pcd.hpp"
#include "runtime/process.hpp"
#include "io/atomic_file.hpp"
#include "drivers/udp_sender.hpp"
#include "sources/sim_bag.hpp"
#include "sources/sim_lidar_udp.hpp"
#include "sources/sim_pcap.hpp"
#include "sources/sim_source.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>

namespace {

struct SimArgs {
  std::vector<std::string> configs;
  std::string world, sensor, output, gt, world_pcd, lcm_url, pcap, bag, bag_compression = "none", lidar_udp;
  double duration_s = -1, rate = 1.0, world_spacing = 0.1, start_speed = -1, start_distance = -1;
  bool reverse = false, stationary = false;
  std::int64_t seed = -1;
  bool live = false, no_truth_channel = false, no_imu = false, wheel_odom = false;
  std::string stall_lidar, stall_imu;
};

// "START:SECONDS" (seconds of sensor time after the first message) -> a stall.
adit::sources::SimStall parseStall(const std::string& text, const std::string& flag) {
  adit::sources::SimStall stall;
  if (text.empty()) return stall;
  const auto colon = text.find(':');
  try {
    if (colon == std::string::npos) throw std::invalid_argument("no colon");
    std::size_t used = 0;
    stall.start_s = std::stod(text.substr(0, colon), &used);
    if (used != colon) throw std::invalid_argument("trailing characters");
    stall.duration_s = std::stod(text.substr(colon + 1), &used);
    if (used != text.size() - colon - 1) throw std::invalid_argument("trailing characters");
  } catch (const std::exception&) {
    throw CLI::ValidationError(flag, "expects START:SECONDS (e.g. 20:10), got '" + text + "'");
  }
  if (!(stall.start_s >= 0) || !(stall.duration_s > 0))
    throw CLI::ValidationError(flag, "START must be >= 0 and SECONDS > 0, got '" + text + "'");
  return stall;
}

// A file written beside the run (--pcap, --bag): `attach` hooks its recorder to the source and returns what
// completes the file once the run has ended; `done` reports it.
struct Recording {
  std::string path;
  std::function<std::function<void()>(adit::sources::SimSource&, std::ostream&)> attach;
  std::function<void()> done;
};

// Runs `source` (the simulator, or what wraps it) with every recording of `sim` open, each written atomically:
// a failed run leaves none of them.
void runRecording(adit::sources::SimSource& sim, adit::runtime::MessageSource& source,
                  const adit::runtime::SourceRunOptions& run, const std::vector<Recording>& files, std::size_t i = 0) {
  if (i == files.size()) {
    if (const int code = adit::runtime::runSource(source, run); code != 0) throw CLI::RuntimeError(code);
    return;
  }
  adit::io::writeFileAtomically(files[i].path, [&](std::ostream& out) {
    const std::function<void()> complete = files[i].attach(sim, out);
    runRecording(sim, source, run, files, i + 1);
    complete();
  });
  files[i].done();
}

}  // namespace

void registerSimCommand(CLI::App& app) {
  auto a = std::make_shared<SimArgs>();
  auto* cmd = app.add_subcommand("sim", "Simulate a robot with a 16-beam lidar and an IMU in an underground roadway");
  cmd->add_option("--config", a->configs, "YAML with sim.* keys (repeatable; flags below override)");
  cmd->add_option("--world", a->world, "roadway-straight | roadway-loop | room-and-pillar | featureless (default roadway-loop)")
      ->check(CLI::IsMember({"roadway-straight", "roadway-loop", "room-and-pillar", "featureless"}));
  cmd->add_option("--sensor", a->sensor, "vlp16 | rs16 | hdl64 (default vlp16)")->check(CLI::IsMember({"vlp16", "rs16", "hdl64"}));
  cmd->add_option("--duration", a->duration_s, "Simulated seconds (default 60)")->check(CLI::PositiveNumber);
  cmd->add_option("--seed", a->seed, "Seed of the world, the motion and every noise (default 1)")->check(CLI::NonNegativeNumber);
  cmd->add_option("-o,--output", a->output, "LCM log to write (LIDAR_POINTS, IMU, GROUND_TRUTH; WHEEL_ODOM with --wheel-odom)");
  cmd->add_option("--gt", a->gt, "Ground truth as TUM: T_world_lidar at each sweep's utime (its last firing)");
  cmd->add_option("--world-pcd", a->world_pcd, "Also write the world's surfaces as a PCD (for comparing with the map)");
  cmd->add_option("--pcap", a->pcap, "Also write the lidar as the VLP-16 packet capture a real sensor would give "
                 "(classic pcap; --sensor vlp16 only)");
  cmd->add_option("--bag", a->bag, "Also write the run as a ROS 1 bag: /velodyne_points (sensor_msgs/PointCloud2 in the "
                 "ROS Velodyne driver's layout) and /imu/data (sensor_msgs/Imu)");
  cmd->add_option("--bag-compression", a->bag_compression, "Chunk compression of --bag: none (as rosbag record), bz2, lz4")
      ->check(CLI::IsMember({"none", "bz2", "lz4"}));
  cmd->add_option("--world-spacing", a->world_spacing, "Point spacing of --world-pcd (m)")->check(CLI::PositiveNumber);
  cmd->add_flag("--live", a->live, "Publish over LCM in real time instead of writing a log");
  cmd->add_option("--rate", a->rate, "With --live: multiple of real time (0 = as fast as possible)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--lcm-url", a->lcm_url, "With --live: LCM provider (default: $LCM_DEFAULT_URL or udpm)");
  cmd->add_option("--lidar-udp", a->lidar_udp,
                  "With --live (vlp16): send the lidar as VLP-16 UDP packets to HOST:PORT instead of LIDAR_POINTS, "
                  "for adit-lidar-bridge (launch/sim-packets.launch.yaml); the clock starts at the wall clock, as "
                  "the packets' stamps are UTC (so the run must stay within half an hour of it)");
  cmd->add_flag("--no-ground-truth-channel", a->no_truth_channel, "Do not publish GROUND_TRUTH");
  cmd->add_option("--start-speed", a->start_speed,
                  "Already driving at this speed (m/s) at time 0, as a log cut from a drive (sim.motion.start_speed; "
                  "raise sim.motion.cruise_speed / max_speed with it for a road vehicle)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--start-distance", a->start_distance,
                  "Start this far (m) along the world's route (sim.motion.start_distance): a later drive through "
                  "the same roadway")->check(CLI::NonNegativeNumber);
  cmd->add_flag("--reverse", a->reverse, "Drive the route backwards (sim.motion.reverse)");
  cmd->add_flag("--stationary", a->stationary,
                "The robot stands still at the route's start for the whole run (sim.motion.stationary; "
                "sim.motion.idle_vibration: chassis vibration at rest)");
  cmd->add_flag("--no-imu", a->no_imu, "Publish no IMU (a vehicle without one)");
  cmd->add_flag("--wheel-odom", a->wheel_odom,
                "Also publish WHEEL_ODOM: track odometry with 3-8 % slip and noise (sim.wheel.enabled; sim.wheel.*)");
  cmd->add_option("--stall-lidar", a->stall_lidar,
                  "Fault test: publish no LIDAR_POINTS (nor their GROUND_TRUTH) from START for SECONDS of sensor "
                  "time (START:SECONDS)");
  cmd->add_option("--stall-imu", a->stall_imu, "Fault test: publish no IMU from START for SECONDS (START:SECONDS)");
  cmd->callback([a] {
    if (a->live == !a->output.empty()) throw CLI::ValidationError("adit sim", "give either -o LOG or --live");
    std::string udp_host;
    std::uint16_t udp_port = 0;
    if (!a->lidar_udp.empty()) {
      if (!a->live || !(a->rate > 0))
        throw CLI::ValidationError("--lidar-udp", "needs --live at a --rate above 0 (the packets' stamps are UTC)");
      try {
        adit::drivers::parseUdpAddress(a->lidar_udp, udp_host, udp_port);
      } catch (const std::invalid_argument& e) {
        throw CLI::ValidationError("--lidar-udp", e.what());
      }
    }
    // The flags go into the configuration before it is resolved: the world's geometry depends on the world's
    // name and the seed (a --world set afterwards used to build the file's or the default world).
    adit::Config file = adit::runtime::loadConfig(a->configs);
    if (!a->world.empty()) file.set("sim.world", a->world);
    if (!a->sensor.empty()) file.set("sim.sensor", a->sensor);
    if (a->seed >= 0) file.set("sim.seed", std::to_string(a->seed));
    if (a->wheel_odom) file.set("sim.wheel.enabled", "true");
    adit::sim::SimConfig config = adit::sim::simConfigFrom(file);
    if (a->duration_s > 0) config.duration_s = a->duration_s;
    if (a->start_speed >= 0) config.motion.start_speed = a->start_speed;
    if (a->start_distance >= 0) config.motion.start_distance = a->start_distance;
    if (a->reverse) config.motion.reverse = true;
    if (a->stationary) config.motion.stationary = true;
    // A sensor's packets carry UTC stamps: the simulated clock is the host's, to the millisecond. A VLP-16 stamp
    // is microseconds past the hour, which the bridge takes from its own clock: away from real time the two
    // clocks part (the bridge counts clock_not_utc), and beyond half an hour it would read the wrong hour.
    if (!a->lidar_udp.empty()) {
      if (config.duration_s * std::abs(1.0 - 1.0 / a->rate) >= 1800.0)
        throw CLI::ValidationError("--lidar-udp", "at --rate " + fmt::format("{:g}", a->rate) + " the simulated clock of a " +
                                                      fmt::format("{:g}", config.duration_s) +
                                                      " s run leaves the wall clock by half an hour or more");
      config.start_utime = adit::runtime::wallUtime() / 1000 * 1000;
    }

    adit::sources::SimChannels channels;
    if (a->no_truth_channel) channels.ground_truth.clear();
    if (a->no_imu) channels.imu.clear();
    channels.sweep_bytes = a->lidar_udp.empty();  // --lidar-udp: the sweeps leave as packets
    const adit::sources::SimStalls stalls{parseStall(a->stall_lidar, "--stall-lidar"),
                                          parseStall(a->stall_imu, "--stall-imu")};
    adit::sources::SimSource source(config, channels, stalls);
    fmt::print("sim: world {} ({:.0f} m route), sensor {}, {:.0f} s, seed {}: {} sweeps\n", config.world,
               source.simulator().lapLength(), config.sensor, config.duration_s, config.seed,
               source.simulator().numSweeps());
    if (!a->world_pcd.empty()) {
      std::vector<adit::LidarPoint> points;
      for (const auto& p : source.simulator().worldPointCloud(a->world_spacing)) points.push_back({p, 0.0f, 0, 0.0f});
      adit::io::writePcd(a->world_pcd, points);
      fmt::print("sim: wrote world ({} points) to {}\n", points.size(), a->world_pcd);
    }
    adit::runtime::SourceRunOptions run;
    run.process = "sim";
    run.output_log = a->output;
    run.lcm_url = a->lcm_url;
    run.rate = a->rate;
    std::vector<Recording> files;
    if (!a->pcap.empty()) {
      auto packets = std::make_shared<std::int64_t>(0);
      files.push_back({a->pcap,
                       [packets](adit::sources::SimSource& sim, std::ostream& out) -> std::function<void()> {
                         auto recorder = std::make_shared<adit::sources::SimPcapRecorder>(sim.simulator().lidar(), out);
                         sim.addSweepObserver([recorder](const adit::LidarScan& scan) { recorder->addSweep(scan); });
                         return [recorder, packets] { *packets = recorder->packets(); };
                       },
                       [packets, path = a->pcap] { fmt::print("sim: wrote {} VLP-16 packets to {}\n", *packets, path); }});
    }
    if (!a->bag.empty()) {
      auto messages = std::make_shared<std::int64_t>(0);
      files.push_back({a->bag,
                       [messages, compression = a->bag_compression](adit::sources::SimSource& sim,
                                                                    std::ostream& out) -> std::function<void()> {
                         auto recorder = std::make_shared<adit::sources::SimBagRecorder>(out, compression);
                         sim.addSweepObserver([recorder](const adit::LidarScan& scan) { recorder->addSweep(scan); });
                         sim.addImuObserver([recorder](const adit::ImuSample& s) { recorder->addImu(s); });
                         return [recorder, messages] {
                           recorder->finish();
                           *messages = recorder->messages();
                         };
                       },
                       [messages, path = a->bag] { fmt::print("sim: wrote {} bag messages to {}\n", *messages, path); }});
    }
    if (a->lidar_udp.empty()) {
      runRecording(source, source, run, files);
    } else {
      adit::sources::SimLidarUdpSource link(source, udp_host, udp_port);
      fmt::print("sim: lidar as VLP-16 packets to {}\n", a->lidar_udp);
      runRecording(source, link, run, files);
    }
    if (!a->gt.empty()) {
      adit::eval::writeTum(a->gt, source.groundTruth());
      fmt::print("sim: wrote ground truth ({} poses) to {}\n", source.groundTruth().size(), a->gt);
    }
  });
}
