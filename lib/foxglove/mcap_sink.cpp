#include "foxglove/mcap_sink.hpp"

namespace adit::foxglove {

void McapSink::publish(const std::string& topic, const SchemaText& schema, const std::string& json, std::uint64_t log_ns) {
  auto channel = channels_.find(topic);
  if (channel == channels_.end()) {
    auto id = schemas_.find(schema.name);
    if (id == schemas_.end()) id = schemas_.emplace(schema.name, writer_.addSchema(schema.name, "jsonschema", schema.json)).first;
    channel = channels_.emplace(topic, writer_.addChannel(id->second, topic, "json")).first;
  }
  writer_.write(channel->second, log_ns, log_ns, json);
}

}  // namespace adit::foxglove
