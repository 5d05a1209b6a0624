// What adit-lan-relay forwards from the robot's local bus to the LAN: the monitoring scope. Pure (no LCM
// sockets): a channel and its bytes in, the bytes to forward (or nothing) out, so the rule is tested alone.
#pragma once

#include "runtime/node.hpp"

#include <map>
#include <optional>
#include <regex>
#include <string>

namespace adit::sources {

struct RelayPolicyConfig {
  std::string channels;    // regex (whole name) of the channels that cross
  std::string poses_only;  // regex of odometry_t channels among them forwarded as the pose alone (points stripped)
  std::map<std::string, int> every;  // channel -> forward one message in N (decimation), N >= 1
};

class RelayPolicy {
 public:
  // Throws std::runtime_error on a bad regex or a decimation below 1.
  explicit RelayPolicy(const RelayPolicyConfig& config);

  bool crosses(const std::string& channel) const;
  // The bytes to publish on the LAN for this message, or nothing (not in scope, decimated away, or a
  // pose-only channel whose message is not an odometry_t).
  std::optional<runtime::Bytes> forward(const std::string& channel, const runtime::Bytes& data);

 private:
  RelayPolicyConfig config_;
  std::regex channels_, poses_only_;
  std::map<std::string, std::int64_t> seen_;  // messages seen per decimated channel
};

// "CHANNEL=N" -> {CHANNEL, N}; throws std::runtime_error on anything else.
std::pair<std::string, int> parseEvery(const std::string& spec);

}  // namespace adit::sources
