// What a Foxglove client asks of adit view (Foxglove WebSocket protocol, the client's text messages): subscribe
// and unsubscribe. Read by a small scanner, not std::regex (libstdc++'s regex recurses once per character
// matched: one 60 kB message from any browser on the LAN overflowed adit view's stack) and not std::stol
// (a 20-digit id threw out of the view loop); numbers beyond 32 bits are ignored.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace adit::foxglove {

struct ClientRequest {
  enum class Op { kOther, kSubscribe, kUnsubscribe } op = Op::kOther;
  std::vector<std::pair<std::uint32_t, int>> subscribe;  // (subscription id, channel id)
  std::vector<std::uint32_t> unsubscribe;                 // subscription ids
};

// {"op":"subscribe","subscriptions":[{"id":0,"channelId":3},...]} (keys in any order) or
// {"op":"unsubscribe","subscriptionIds":[0,...]}; anything else is kOther.
ClientRequest parseClientRequest(const std::string& text);

}  // namespace adit::foxglove
