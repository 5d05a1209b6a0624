#include "runtime/node.hpp"

#include <adit/command_t.hpp>

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <limits>
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

std::vector<std::string> Node::outputChannels() const {
  std::vector<std::string> out;
  for (const auto& kv : seq_) out.push_back(channels_.at(kv.first));
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
    const double cpu0 = threadCpuMs();
    try {
      kv.second.handle(data, size);
    } catch (const std::exception& e) {
      // A stage that throws on one input must not take the process down: count it and go on.
      reportError("stage_exception", std::string("stage failed on ") + channel + ": " + e.what());
    }
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const double cpu_ms = threadCpuMs() - cpu0;
    if (kv.first == primary_port_) {
      timing_.add(ms);
      cpu_timing_.add(cpu_ms);
    }
    health_.busy_s += ms * 1e-3;
    wall_ms_total_ += ms;
    cpu_ms_total_ += cpu_ms;
    countHelperCpu();
    sink_ = nullptr;
  }
}

void Node::countHelperCpu() {
  if (const double ms = helperCpuMs(); ms >= 0.0) setCount("helper_cpu_ms", static_cast<std::int64_t>(ms));
}

void Node::finish(Sink& sink) {
  for (auto& kv : inputs_) dropHeld(kv.second);  // never confirmed: counted, not delivered
  sink_ = &sink;
  try {
    onFinish();
  } catch (const std::exception& e) {
    reportError("stage_exception", std::string("finish failed: ") + e.what());
  }
  countHelperCpu();  // the work finish() waited for
  sink_ = nullptr;
}

bool Node::wireOk(const std::string& port, const msg::WireCheck& check, std::size_t size) {
  if (check.ok() && size <= static_cast<std::size_t>(std::numeric_limits<int>::max())) return true;
  const bool oversized = !check.ok() ? check.verdict == msg::WireVerdict::Oversized : true;
  reportError(oversized ? "oversized_count" : "decode_error",
              (oversized ? "oversized" : "undecodable") + std::string(" message on ") + channels_.at(port) + " (" +
                  std::to_string(size) + " bytes): " + (check.ok() ? "too large" : check.reason) + ": skipped");
  return false;
}

bool Node::valuesOk(const std::string& port, const msg::Validation& invalid) {
  if (!invalid) return true;
  reportError(invalid->counter, channels_.at(port) + ": " + invalid->reason + ": skipped");
  return false;
}

std::int64_t Node::Input::typicalStep() const {
  if (recent_steps.size() < 3) return 0;
  std::vector<std::int64_t> sorted = recent_steps;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  return sorted[sorted.size() / 2];
}

bool Node::continuesStream(const Input& input, std::int64_t utime) const {
  const auto tolerance = static_cast<std::int64_t>(checks_.max_future_s * 1e6);
  if (input.last_utime >= 0 && utime <= input.last_utime) return false;
  if (input.kind == InputKind::Stream && input.last_utime >= 0) {
    const std::int64_t period = input.typicalStep();
    if (period > 0 && static_cast<double>(utime - input.last_utime) > checks_.max_step_periods * period) return false;
  }
  // Written so that no utime, however corrupt, overflows the arithmetic (newest_utime_ >= 0 past the first test).
  return newest_utime_ < 0 || utime <= newest_utime_ || utime - newest_utime_ <= tolerance;
}

void Node::dropHeld(Input& input) {
  for (const Held& h : input.held) {
    const bool future = h.utime > input.last_utime;
    reportDrop(future ? "time_future" : "time_backwards",
               channels_.at(input.port) + ": utime " + std::to_string(h.utime) + (future ? " is too far ahead of " : " is before ") +
                   std::to_string(future ? newest_utime_ : input.last_utime) + " and the stream did not continue from it: skipped");
  }
  input.held.clear();
}

void Node::admit(Input& input, Held message) {
  if (input.kind == InputKind::Requests) {
    accept(input, message);
    return;
  }
  if (input.last_utime >= 0 && message.utime == input.last_utime) {
    reportDrop("duplicate_time", channels_.at(input.port) + ": utime " + std::to_string(message.utime) +
                                     " repeats: skipped");
    return;
  }
  if (continuesStream(input, message.utime)) {
    dropHeld(input);
    accept(input, message);
    return;
  }
  // Off the stream's time: hold it; a new stream needs confirm_messages consistent successors.
  const auto tolerance = static_cast<std::int64_t>(checks_.max_future_s * 1e6);
  // The difference of two corrupt utimes can exceed int64 (INT64_MIN then a real time): taken unsigned, it is
  // exact because the first is the larger.
  const bool chained = !input.held.empty() && message.utime > input.held.back().utime &&
                       static_cast<std::uint64_t>(message.utime) - static_cast<std::uint64_t>(input.held.back().utime) <=
                           static_cast<std::uint64_t>(tolerance);
  if (!chained) dropHeld(input);
  input.held.push_back(std::move(message));
  if (static_cast<int>(input.held.size()) <= checks_.confirm_messages) return;

  std::vector<Held> stream = std::move(input.held);
  input.held.clear();
  const std::string& channel = channels_.at(input.port);
  if (input.last_utime >= 0 && stream.front().utime < input.last_utime) {
    count("time_resync");
    spdlog::warn("[{}] {}: time restarted ({} after {}), confirmed by {} messages: following it", name_, channel,
                 stream.front().utime, input.last_utime, stream.size());
    input.last_utime = -1;
    if (input.kind == InputKind::Stream) newest_utime_ = -1;  // other inputs follow it, or re-synchronise too
    if (input.kind == InputKind::Stream) onTimeJump(input.port);
  } else {
    spdlog::warn("[{}] {}: time moved ahead to {}, confirmed by {} messages: following it", name_, channel,
                 stream.front().utime, stream.size());
  }
  for (Held& h : stream) accept(input, h);
}

void Node::accept(Input& input, Held& message) {
  countSequence(input, message.seq);
  if (input.kind != InputKind::Requests) {
    const std::int64_t utime = message.utime;
    if (input.kind == InputKind::Stream && input.last_utime >= 0 && utime - input.last_utime > max_time_gap_us_) {
      count("time_jump");
      spdlog::warn("[{}] {}: time jumps forward by {:.3f} s: resetting temporal state", name_,
                   channels_.at(input.port), static_cast<double>(utime - input.last_utime) * 1e-6);
      onTimeJump(input.port);
    }
    if (input.kind == InputKind::Stream && input.last_utime >= 0 && utime > input.last_utime) {
      constexpr std::size_t kSteps = 7;
      if (input.recent_steps.size() == kSteps) input.recent_steps.erase(input.recent_steps.begin());
      input.recent_steps.push_back(utime - input.last_utime);
    }
    input.last_utime = utime;
    if (input.kind == InputKind::Stream) newest_utime_ = std::max(newest_utime_, utime);
    if (utime > health_.last_input_utime) health_.last_input_utime = utime;
  }
  endBursts();
  message.run();
}

void Node::countSequence(Input& input, std::int64_t seq) {
  // Negative or repeated: a publisher that does not number its messages.
  if (seq < 0 || seq == input.last_seq) return;
  if (input.last_seq >= 0) {
    const std::int64_t lost = seq - input.last_seq - 1;
    const std::string& channel = channels_.at(input.port);
    if (seq < input.last_seq || lost > checks_.max_seq_gap) {
      count("seq_reset");
      spdlog::warn("[{}] {}: sequence restarts (seq {} after {}): not counted as lost", name_, channel, seq,
                   input.last_seq);
    } else if (lost > 0) {
      health_.drops += lost;
      count("lost_input", lost);
      spdlog::warn("[{}] {}: {} message(s) lost before arriving (seq {} after {})", name_, channel, lost, seq,
                   input.last_seq);
    }
  }
  input.last_seq = seq;
}

void Node::emit(const std::string& port, Bytes bytes, std::int64_t utime) {
  if (!sink_) throw std::logic_error(name_ + ": publish outside deliver()/finish()");
  ++health_.outputs;
  sink_->publish(channels_.at(port), bytes, utime);
}

void Node::requireSignedCommands(CommandKey key) { command_gate_ = std::make_unique<CommandGate>(std::move(key)); }

bool Node::commandAuthentic(const std::string& port, const adit::command_t& command) {
  if (!command_gate_) return true;
  const std::int64_t now = std::chrono::duration_cast<std::chrono::microseconds>(
                               std::chrono::system_clock::now().time_since_epoch()).count();
  const CommandVerdict verdict = command_gate_->check(channels_.at(port), command.command, command.argument,
                                                      command.counter, command.mac, now);
  if (verdict == CommandVerdict::Authentic) return true;
  reportError(counterName(verdict), "command '" + printableText(command.command) + "' on " + channels_.at(port) +
                                        " refused: " + describe(verdict));
  return false;
}

void Node::reportError(const std::string& counter, const std::string& message) {
  ++health_.errors;
  count(counter);
  health_.last_error = message;
  auto [it, first] = bursts_.emplace(counter, 0);
  if (first) spdlog::error("[{}] {}", name_, message);
  else ++it->second;
}

void Node::reportDrop(const std::string& counter, const std::string& message) {
  ++health_.drops;
  count(counter);
  health_.last_error = message;
  auto [it, first] = bursts_.emplace(counter, 0);
  if (first) spdlog::warn("[{}] {}", name_, message);
  else ++it->second;
}

void Node::endBursts() {
  for (const auto& [counter, repeats] : bursts_)
    if (repeats > 0) spdlog::warn("[{}] {} more input(s) counted as {} (not logged one by one)", name_, repeats, counter);
  bursts_.clear();
}

}  // namespace adit::runtime
