#include "sources/relay_policy.hpp"

#include "msg/convert.hpp"
#include "msg/encode.hpp"

#include <adit/odometry_t.hpp>

#include <stdexcept>

namespace adit::sources {

RelayPolicy::RelayPolicy(const RelayPolicyConfig& config) : config_(config) {
  try {
    channels_ = std::regex(config.channels);
    poses_only_ = std::regex(config.poses_only);
  } catch (const std::regex_error& e) {
    throw std::runtime_error("relay: bad channel regex: " + std::string(e.what()));
  }
  for (const auto& [channel, n] : config.every)
    if (n < 1) throw std::runtime_error("relay: --every " + channel + "=" + std::to_string(n) + ": N must be >= 1");
}

bool RelayPolicy::crosses(const std::string& channel) const { return std::regex_match(channel, channels_); }

std::optional<runtime::Bytes> RelayPolicy::forward(const std::string& channel, const runtime::Bytes& data) {
  if (!crosses(channel)) return std::nullopt;
  if (const auto it = config_.every.find(channel); it != config_.every.end())
    if (seen_[channel]++ % it->second != 0) return std::nullopt;
  if (!config_.poses_only.empty() && std::regex_match(channel, poses_only_)) {
    adit::odometry_t m;
    int used = -1;
    try {
      used = m.decode(data.data(), 0, static_cast<int>(data.size()));
    } catch (const std::exception&) {
      used = -1;
    }
    if (used < 0) return std::nullopt;
    msg::stripPoints(m);
    return msg::encode(m);
  }
  return data;
}

std::pair<std::string, int> parseEvery(const std::string& spec) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0) throw std::runtime_error("--every expects CHANNEL=N, got '" + spec + "'");
  try {
    std::size_t used = 0;
    const int n = std::stoi(spec.substr(eq + 1), &used);
    if (used != spec.size() - eq - 1) throw std::invalid_argument("trailing characters");
    return {spec.substr(0, eq), n};
  } catch (const std::exception&) {
    throw std::runtime_error("--every expects CHANNEL=N with an integer N, got '" + spec + "'");
  }
}

}  // namespace adit::sources
