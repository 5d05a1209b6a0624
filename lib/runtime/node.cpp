#include "runtime/node.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <stdexcept>

namespace adit::runtime {

void Node::remap(const std::string& port, const std::string& channel) {
  auto it = channels_.find(port);
  if (it == channels_.end()) throw std::runtime_error(name_ + ": no port named '" + port + "'");
  it->second = channel;
}

std::vector<std::string> Node::inputChannels() const {
  std::vector<std::string> out;
  for (const auto& kv : inputs_) out.push_back(channels_.at(kv.first));
  return out;
}

bool Node::isInput(const std::string& channel) const {
  for (const auto& kv : inputs_)
    if (channels_.at(kv.first) == channel) return true;
  return false;
}

void Node::advertise(const std::string& port, const std::string& default_channel) {
  channels_.emplace(port, default_channel);
  seq_.emplace(port, 0);
}

void Node::deliver(const std::string& channel, const std::uint8_t* data, std::size_t size, Sink& sink) {
  for (auto& kv : inputs_) {
    if (channels_.at(kv.first) != channel) continue;
    ++health_.inputs;
    sink_ = &sink;
    const auto t0 = std::chrono::steady_clock::now();  // monitoring only: never feeds an algorithm
    try {
      kv.second.handle(data, size);
    } catch (const std::exception& e) {
      // A stage that throws on one input must not take the process down: count it and go on.
      reportError("stage_exception", std::string("stage failed on ") + channel + ": " + e.what());
    }
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (kv.first == primary_port_) timing_.add(ms);
    health_.busy_s += ms * 1e-3;
    sink_ = nullptr;
  }
}

void Node::finish(Sink& sink) {
  sink_ = &sink;
  try {
    onFinish();
  } catch (const std::exception& e) {
    reportError("stage_exception", std::string("finish failed: ") + e.what());
  }
  sink_ = nullptr;
}

bool Node::admit(Input& input, std::int64_t utime, std::int64_t seq) {
  const std::string& channel = channels_.at(input.port);
  // A gap in the publisher's sequence numbers: messages lost on the way (network, full socket buffer).
  if (input.last_seq >= 0 && seq > input.last_seq + 1) {
    health_.drops += seq - input.last_seq - 1;
    count("lost_input", seq - input.last_seq - 1);
    spdlog::warn("[{}] {}: {} message(s) lost before arriving (seq {} after {})", name_, channel,
                 seq - input.last_seq - 1, seq, input.last_seq);
  }
  if (seq >= 0) input.last_seq = seq;
  if (input.kind == InputKind::Requests) return true;
  if (input.last_utime >= 0 && utime <= input.last_utime) {
    reportDrop(utime == input.last_utime ? "duplicate_time" : "time_backwards",
               channel + ": utime " + std::to_string(utime) + " is not after " + std::to_string(input.last_utime) +
                   ": skipped");
    return false;
  }
  if (input.kind == InputKind::Stream && input.last_utime >= 0 && utime - input.last_utime > max_time_gap_us_) {
    count("time_jump");
    spdlog::warn("[{}] {}: time jumps forward by {:.3f} s: resetting temporal state", name_, channel,
                 static_cast<double>(utime - input.last_utime) * 1e-6);
    onTimeJump(input.port);
  }
  input.last_utime = utime;
  if (utime > health_.last_input_utime) health_.last_input_utime = utime;
  return true;
}

void Node::emit(const std::string& port, Bytes bytes, std::int64_t utime) {
  if (!sink_) throw std::logic_error(name_ + ": publish outside deliver()/finish()");
  ++health_.outputs;
  sink_->publish(channels_.at(port), bytes, utime);
}

void Node::reportError(const std::string& counter, const std::string& message) {
  ++health_.errors;
  count(counter);
  health_.last_error = message;
  spdlog::error("[{}] {}", name_, message);
}

void Node::reportDrop(const std::string& counter, const std::string& message) {
  ++health_.drops;
  count(counter);
  health_.last_error = message;
  spdlog::warn("[{}] {}", name_, message);
}

}  // namespace adit::runtime
