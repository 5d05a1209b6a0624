#include "foxglove/foxglove_ws.hpp"

#include "core/json_writer.hpp"

#include <cstring>
#include <regex>

namespace adit::foxglove {

FoxgloveWs::FoxgloveWs(view::WebServer& server, ExportOptions options)
    : server_(server), options_(options), run_(std::make_unique<FoxgloveRun>(static_cast<FoxgloveSink&>(*this), options)) {}

void FoxgloveWs::apply(const std::string& channel, const std::uint8_t* data, std::size_t size, std::int64_t utime) {
  run_->add(channel, data, size, utime);
}

void FoxgloveWs::reset() { run_ = std::make_unique<FoxgloveRun>(static_cast<FoxgloveSink&>(*this), options_); }

std::string FoxgloveWs::advertise(const std::string& topic, const Channel& c) const {
  JsonWriter j;
  j.beginObject().field("op", "advertise").key("channels").beginArray().beginObject();
  j.field("id", c.id).field("topic", topic).field("encoding", "json").field("schemaName", c.schema.name);
  j.field("schema", c.schema.json).field("schemaEncoding", "jsonschema");
  j.endObject().endArray().endObject();
  return j.str();
}

void FoxgloveWs::tick() {
  for (const int id : server_.clients()) {
    if (server_.subprotocol(id) != kFoxgloveSubprotocol || clients_.count(id)) continue;
    clients_[id];
    JsonWriter info;
    info.beginObject().field("op", "serverInfo").field("name", "adit view").key("capabilities").beginArray().endArray();
    info.key("supportedEncodings").beginArray().endArray().endObject();
    server_.send(id, info.str(), -1, 1);
    for (const auto& [topic, c] : channels_) server_.send(id, advertise(topic, c), -1, 1);
  }
}

void FoxgloveWs::publish(const std::string& topic, const SchemaText& schema, const std::string& json, std::uint64_t log_ns) {
  auto it = channels_.find(topic);
  if (it == channels_.end()) {
    it = channels_.emplace(topic, Channel{static_cast<int>(channels_.size()) + 1, schema}).first;
    for (const auto& [id, client] : clients_) server_.send(id, advertise(topic, it->second), -1, 1);
  }
  for (const auto& [id, client] : clients_)
    for (const auto& [subscription, channel] : client.subscriptions) {
      if (channel != it->second.id) continue;
      std::string frame(13, '\0');
      frame[0] = 1;  // message data
      std::memcpy(&frame[1], &subscription, 4);  // little-endian machines, as the protocol
      std::memcpy(&frame[5], &log_ns, 8);
      server_.send(id, frame + json);
    }
}

bool FoxgloveWs::message(int client, const std::string& text) {
  const auto it = clients_.find(client);
  if (it == clients_.end()) return false;
  static const std::regex op(R"re("op"\s*:\s*"(\w+)")re");
  static const std::regex number(R"re("(id|channelId)"\s*:\s*(\d+))re");
  static const std::regex object(R"re(\{[^{}]*\})re");
  std::smatch m;
  if (!std::regex_search(text, m, op)) return true;
  if (m[1] == "subscribe") {
    // {"op":"subscribe","subscriptions":[{"id":0,"channelId":3},...]}: each inner object, keys in any order.
    const auto list = text.find('[');
    for (std::sregex_iterator o(text.begin() + static_cast<long>(list == std::string::npos ? 0 : list), text.end(), object), end;
         o != end; ++o) {
      const std::string one = o->str();
      long sub = -1, channel = -1;
      for (std::sregex_iterator n(one.begin(), one.end(), number); n != std::sregex_iterator(); ++n)
        ((*n)[1] == "id" ? sub : channel) = std::stol((*n)[2]);
      if (sub >= 0 && channel >= 0) it->second.subscriptions[static_cast<std::uint32_t>(sub)] = static_cast<int>(channel);
    }
  } else if (m[1] == "unsubscribe") {
    const auto list = text.find('[');
    static const std::regex id(R"(\d+)");
    for (std::sregex_iterator n(text.begin() + static_cast<long>(list == std::string::npos ? text.size() : list), text.end(), id), end;
         n != end; ++n)
      it->second.subscriptions.erase(static_cast<std::uint32_t>(std::stoul(n->str())));
  }
  return true;
}

}  // namespace adit::foxglove
