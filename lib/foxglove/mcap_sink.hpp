// FoxgloveRun's messages into an MCAP file (adit export mcap): a schema and a channel per topic, made when
// the topic first appears; JSON messages.
#pragma once

#include "foxglove/foxglove_run.hpp"
#include "io/mcap_writer.hpp"

#include <map>
#include <string>

namespace adit::foxglove {

class McapSink : public FoxgloveSink {
 public:
  explicit McapSink(io::McapWriter& writer) : writer_(writer) {}
  void publish(const std::string& topic, const SchemaText& schema, const std::string& json, std::uint64_t log_ns) override;

 private:
  io::McapWriter& writer_;
  std::map<std::string, std::uint16_t> schemas_, channels_;
};

}  // namespace adit::foxglove
