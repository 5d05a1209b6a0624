#include "foxglove/foxglove_client.hpp"

#include <cctype>
#include <limits>
#include <optional>

namespace adit::foxglove {
namespace {

bool isDigit(char c) { return c >= '0' && c <= '9'; }

std::size_t skipSpace(const std::string& t, std::size_t i) {
  while (i < t.size() && std::isspace(static_cast<unsigned char>(t[i]))) ++i;
  return i;
}

// The digits at i as a number (nullopt beyond 32 bits); `end` is set past them.
std::optional<std::uint32_t> digitsAt(const std::string& t, std::size_t i, std::size_t& end) {
  std::uint64_t value = 0;
  bool fits = true;
  for (end = i; end < t.size() && isDigit(t[end]); ++end) {
    value = value * 10 + static_cast<std::uint64_t>(t[end] - '0');
    if (value > std::numeric_limits<std::uint32_t>::max()) {
      fits = false;
      value = 0;
    }
  }
  if (end == i || !fits) return std::nullopt;
  return static_cast<std::uint32_t>(value);
}

// After a quoted key ending at i (its closing quote): optional space, ':', optional space; the value's start
// or npos.
std::size_t valueAfterKey(const std::string& t, std::size_t i) {
  i = skipSpace(t, i + 1);
  if (i >= t.size() || t[i] != ':') return std::string::npos;
  return skipSpace(t, i + 1);
}

// The value of the first "op": "word".
std::string opOf(const std::string& t) {
  for (std::size_t at = t.find("\"op\""); at != std::string::npos; at = t.find("\"op\"", at + 1)) {
    std::size_t v = valueAfterKey(t, at + 3);
    if (v == std::string::npos || v >= t.size() || t[v] != '"') continue;
    std::size_t e = v + 1;
    while (e < t.size() && (std::isalnum(static_cast<unsigned char>(t[e])) || t[e] == '_')) ++e;
    if (e < t.size() && t[e] == '"' && e > v + 1) return t.substr(v + 1, e - v - 1);
  }
  return "";
}

// One {...} without braces inside: its "id" and "channelId" (the last of each).
void subscription(const std::string& t, std::size_t begin, std::size_t end, ClientRequest& out) {
  std::optional<std::uint32_t> id, channel;
  for (std::size_t q = t.find('"', begin); q < end; q = t.find('"', q + 1)) {
    const std::size_t close = t.find('"', q + 1);
    if (close >= end) break;
    const std::string key = t.substr(q + 1, close - q - 1);
    q = close;
    if (key != "id" && key != "channelId") continue;
    const std::size_t v = valueAfterKey(t, close);
    std::size_t after = 0;
    if (v == std::string::npos || v >= end) continue;
    const std::optional<std::uint32_t> number = digitsAt(t, v, after);
    if (!number) continue;
    (key == "id" ? id : channel) = number;
  }
  if (id && channel && *channel <= static_cast<std::uint32_t>(std::numeric_limits<int>::max()))
    out.subscribe.emplace_back(*id, static_cast<int>(*channel));
}

}  // namespace

ClientRequest parseClientRequest(const std::string& t) {
  ClientRequest out;
  const std::string op = opOf(t);
  const std::size_t list = t.find('[');
  if (op == "subscribe") {
    out.op = ClientRequest::Op::kSubscribe;
    std::size_t open = std::string::npos;
    for (std::size_t i = list == std::string::npos ? 0 : list; i < t.size(); ++i) {
      if (t[i] == '{') {
        open = i;
      } else if (t[i] == '}' && open != std::string::npos) {
        subscription(t, open, i, out);
        open = std::string::npos;
      }
    }
  } else if (op == "unsubscribe") {
    out.op = ClientRequest::Op::kUnsubscribe;
    for (std::size_t i = list == std::string::npos ? t.size() : list; i < t.size();) {
      if (!isDigit(t[i])) {
        ++i;
        continue;
      }
      std::size_t end = i;
      if (const std::optional<std::uint32_t> id = digitsAt(t, i, end)) out.unsubscribe.push_back(*id);
      i = end;
    }
  }
  return out;
}

}  // namespace adit::foxglove
