// Something fed a run's LCM messages in order (adit view's page session, the Foxglove WebSocket side), and
// told when the run starts over (a log rewound). Fanout feeds several.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace adit::view {

class RunConsumer {
 public:
  virtual ~RunConsumer() = default;
  // utime: the message's log (receive) time, microseconds.
  virtual void apply(const std::string& channel, const std::uint8_t* data, std::size_t size, std::int64_t utime) = 0;
  virtual void reset() = 0;
};

class Fanout : public RunConsumer {
 public:
  void add(RunConsumer& c) { consumers_.push_back(&c); }
  void apply(const std::string& channel, const std::uint8_t* data, std::size_t size, std::int64_t utime) override {
    for (RunConsumer* c : consumers_) c->apply(channel, data, size, utime);
  }
  void reset() override {
    for (RunConsumer* c : consumers_) c->reset();
  }

 private:
  std::vector<RunConsumer*> consumers_;
};

}  // namespace adit::view
