// Bus messages through the runtime's decode-and-check path of every pipeline node (Node::deliver): the
// generated LCM decoder, type and time checks, then the stage itself on whatever decoded.
// Input: one byte choosing the node, then messages as [byte choosing the input channel][uint16 size][bytes].
#include "fuzz_input.hpp"
#include "nodes/registry.hpp"

#include <spdlog/spdlog.h>

#include <memory>

namespace {

class DiscardSink : public adit::runtime::Sink {
 public:
  void publish(const std::string&, const adit::runtime::Bytes&, std::int64_t) override {}
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool quiet = (spdlog::set_level(spdlog::level::off), true);  // one log line per bad input: slow
  (void)quiet;
  adit::fuzz::Input in(data, size);
  const auto& names = adit::nodes::pipelineNodeNames();
  const std::unique_ptr<adit::runtime::Node> node =
      adit::nodes::makeNode(names[in.byte() % names.size()], adit::Config{});
  const std::vector<std::string> channels = node->inputChannels();
  DiscardSink sink;
  while (in.remaining() > 0) {
    const std::string& channel = channels[in.byte() % channels.size()];
    const std::string message = in.bytes(in.u16());
    node->deliver(channel, reinterpret_cast<const std::uint8_t*>(message.data()), message.size(), sink);
  }
  node->finish(sink);
  return 0;
}
