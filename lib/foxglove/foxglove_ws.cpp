#include "foxglove/foxglove_ws.hpp"

#include "core/json_writer.hpp"
#include "foxglove/foxglove_client.hpp"

#include <cstring>

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
  const ClientRequest request = parseClientRequest(text);
  for (const auto& [subscription, channel] : request.subscribe) it->second.subscriptions[subscription] = channel;
  for (const std::uint32_t subscription : request.unsubscribe) it->second.subscriptions.erase(subscription);
  return true;
}

}  // namespace adit::foxglove
