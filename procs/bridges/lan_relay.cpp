// adit-lan-relay: forwards the monitoring channels from the robot's local bus (ttl=0, where the heavy stage
// channels stay) to the LAN (another multicast group, ttl=1): poses, STATUS, loop events, map updates and a
// decimated sweep. One process, one place for the scope, so the stages never need to know about the LAN and a
// monitoring laptop cannot flood the robot's link. STATUS_LAN_RELAY reports what crossed, per channel.
#include "runtime/process.hpp"
#include "runtime/status.hpp"
#include "sources/relay_policy.hpp"

#include <lcm/lcm-cpp.hpp>
#include <spdlog/spdlog.h>

#include <chrono>

namespace {

class Relay {
 public:
  Relay(adit::sources::RelayPolicy& policy, lcm::LCM& lan, adit::runtime::PublishedTraffic& traffic,
        adit::runtime::Health& health)
      : policy_(policy), lan_(lan), traffic_(traffic), health_(health) {}

  void onMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    ++health_.inputs;
    const auto* data = static_cast<const std::uint8_t*>(rbuf->data);
    const auto out = policy_.forward(channel, adit::runtime::Bytes(data, data + rbuf->data_size));
    if (!out) return;
    lan_.publish(channel, out->data(), static_cast<unsigned int>(out->size()));
    traffic_.add(channel, out->size());
    ++health_.outputs;
  }

 private:
  adit::sources::RelayPolicy& policy_;
  lcm::LCM& lan_;
  adit::runtime::PublishedTraffic& traffic_;
  adit::runtime::Health& health_;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Forward the monitoring channels from the robot's local LCM bus to the LAN", "adit-lan-relay"};
  std::string local_url, lan_url;
  std::vector<std::string> every;
  adit::sources::RelayPolicyConfig config;
  config.channels = "^(ODOM_MAPPED|POSE_GRAPH|LOOP_CLOSURE|MAP_UPDATE|STATUS_.*|LIDAR_POINTS)$";
  config.poses_only = "^(ODOM_SCAN|ODOM_MAPPED)$";
  double status_period_s = 1.0;
  app.add_option("--local-url", local_url, "The robot's bus (default: $LCM_DEFAULT_URL)");
  app.add_option("--lan-url", lan_url, "The LAN: another multicast group or port than the local bus, ttl=1")->required();
  app.add_option("--channels", config.channels, "Regex (whole name) of the channels that cross")->capture_default_str();
  app.add_option("--poses-only", config.poses_only, "Regex of odometry_t channels forwarded as the pose alone")
      ->capture_default_str();
  app.add_option("--every", every, "CHANNEL=N: forward one message in N on that channel (repeatable)");
  app.add_option("--status-period", status_period_s, "Seconds between STATUS messages")->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  spdlog::set_pattern("%H:%M:%S.%e %^%l%$ adit-lan-relay: %v");

  try {
    for (const auto& e : every) config.every.insert(adit::sources::parseEvery(e));
    adit::sources::RelayPolicy policy(config);
    const char* env_url = std::getenv("LCM_DEFAULT_URL");
    const std::string local = !local_url.empty() ? local_url : env_url ? env_url : "";
    // The same group and port would hand every forwarded message back to the relay: a loop.
    if (local == lan_url) throw std::runtime_error("--lan-url must differ from the local bus URL (" + local + ")");
    lcm::LCM in(local), lan(lan_url);
    if (!in.good() || !lan.good()) throw std::runtime_error("cannot open LCM '" + (in.good() ? lan_url : local) + "'");

    adit::runtime::PublishedTraffic traffic;
    adit::runtime::Health health;
    Relay relay(policy, lan, traffic, health);
    in.subscribe(config.channels, &Relay::onMessage, &relay);
    adit::runtime::installStopHandlers();
    spdlog::info("relaying '{}' to {} (poses only: '{}')", config.channels, lan_url, config.poses_only);

    const auto start = std::chrono::steady_clock::now();
    auto last_status = start;
    std::int64_t seq = 0, inputs_at_last = 0;
    adit::runtime::TimingWindow no_timing;
    const auto sendStatus = [&](const std::string& state) {
      const auto now = std::chrono::steady_clock::now();
      const double window = std::chrono::duration<double>(now - last_status).count();
      const double rate = window > 0 ? static_cast<double>(health.inputs - inputs_at_last) / window : 0.0;
      adit::status_t s = adit::runtime::makeStatus("lan-relay", health, no_timing, adit::runtime::wallUtime(), seq++,
                                                   std::chrono::duration<double>(now - start).count(), rate, 0.0, state);
      traffic.report(s, window);
      // On the local bus, like every process's STATUS: it crosses to the LAN with the others.
      in.publish(adit::runtime::statusChannel("lan-relay"), &s);
      last_status = now;
      inputs_at_last = health.inputs;
    };
    sendStatus("starting");
    while (!adit::runtime::stopRequested()) {
      if (in.handleTimeout(100) < 0) break;
      if (std::chrono::steady_clock::now() - last_status >= std::chrono::duration<double>(status_period_s))
        sendStatus("running");
    }
    sendStatus("stopping");
    spdlog::info("{} messages in scope seen, {} forwarded", health.inputs, health.outputs);
    return 0;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}
