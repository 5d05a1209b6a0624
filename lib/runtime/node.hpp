// A node is one pipeline stage with LCM-typed inputs and outputs: it decodes what arrives on its input
// channels, calls its (pure) stage, and publishes encoded results. The same node object runs live inside a
// process (runtime/process.hpp) and in lockstep with other nodes in `adit replay` (runtime/lockstep.hpp),
// so there is one code path from message to result.
//
// Inputs are checked before the stage sees them, in this order, each failure counted on STATUS and logged
// once per burst, never thrown:
//   1. wire layout (msg/wire_check.hpp): counts and string lengths bounded by the bytes present and a sane
//      maximum, before the generated decoder allocates anything (decode_error / oversized_count);
//   2. decoding (decode_error);
//   3. values (msg/validate.hpp): finite, physically possible, unit quaternions, bounded strings (invalid_*);
//   4. time and sequence (admit()): see InputChecks.
#pragma once

#include "core/thread_cpu.hpp"
#include "msg/encode.hpp"
#include "msg/validate.hpp"
#include "msg/wire_check.hpp"
#include "runtime/command_auth.hpp"
#include "runtime/health.hpp"
#include "runtime/run_folder.hpp"

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace adit {
class command_t;
}

namespace adit::runtime {

using Bytes = std::vector<std::uint8_t>;

// How an input's timing is checked before its handler runs.
enum class InputKind {
  Stream,    // sensor data at a steady rate: time must advance; a forward gap is a time jump
  Events,    // sparse results (loop closures, graphs): time must advance; gaps are normal
  Requests,  // commands: no time checks
};

// How far an input's time and sequence numbers are trusted. All decisions use message stamps and arrival
// order only (never the wall clock), so replay stays deterministic.
struct InputChecks {
  // A stamp further than this ahead of the newest sensor time the node has accepted (on any Stream input;
  // an Events input is checked against it only, so sparse results may be minutes apart) is not adopted
  // at once: the message is held. If the next `confirm_messages` messages continue from it (each later, by
  // at most this much), the stream really moved (a sensor stalled and resumed): the held messages are
  // delivered and the gap reported as a time jump. If a message continues the old time instead, the held
  // ones were forged or corrupt: dropped and counted as time_future. The same confirmation re-synchronises
  // a stream that goes persistently backwards (a sensor clock restarted): counted as time_resync; an
  // isolated backwards stamp is dropped as time_backwards.
  double max_future_s = 2.0;
  int confirm_messages = 2;
  // On a Stream, a step forward of more than this many of the stream's typical periods (the median of its
  // last steps) needs the same confirmation, even when it is within max_future_s: one message stamped 1 s
  // ahead would otherwise be adopted, and the valid messages of that second dropped as going backwards (the
  // mutation campaign moved the odometry 18.8 km that way). A real gap (lost messages, a stall) only delays
  // the first messages after it by confirm_messages.
  double max_step_periods = 4.0;
  // A sequence-number gap larger than this (or a number that goes back) is a restarted or forged publisher,
  // counted once as seq_reset, not as that many lost messages.
  std::int64_t max_seq_gap = 10000;
  msg::WireLimits wire;
  msg::InputLimits values;
};

// Where a node's output goes (LCM in a process, the in-process bus in replay).
class Sink {
 public:
  virtual ~Sink() = default;
  virtual void publish(const std::string& channel, const Bytes& data, std::int64_t utime) = 0;
};

class Node {
 public:
  explicit Node(std::string name) : name_(std::move(name)) {}
  virtual ~Node() = default;
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;

  const std::string& name() const { return name_; }

  // Logical port -> channel name. Ports are declared by the subclass; remap before running.
  void remap(const std::string& port, const std::string& channel);
  const std::map<std::string, std::string>& channels() const { return channels_; }
  std::vector<std::string> inputChannels() const;
  bool isInput(const std::string& channel) const;
  // Channels of the advertised output ports.
  std::vector<std::string> outputChannels() const;

  // Hand one encoded message that arrived on `channel` to the node; its outputs go to `sink`.
  void deliver(const std::string& channel, const std::uint8_t* data, std::size_t size, Sink& sink);
  // No more input will come (end of log, shutdown): publish what is pending.
  void finish(Sink& sink);

  const Health& health() const { return health_; }
  // Processing time of the node's first input (its main one: a sweep, not the IMU samples in between).
  const TimingWindow& timing() const { return timing_; }
  TimingWindow& timing() { return timing_; }
  // The same calls' CPU time of the delivering thread (a stage's own worker threads are not in it), and the
  // totals over every input (ms; monitoring only).
  const TimingWindow& cpuTiming() const { return cpu_timing_; }
  TimingWindow& cpuTiming() { return cpu_timing_; }
  double wallMsTotal() const { return wall_ms_total_; }
  double cpuMsTotal() const { return cpu_ms_total_; }
  // Latency a live process measures and reports on STATUS (runtime/latency.hpp): from a message's arrival
  // on origin_channel to this node's output on output_port with the same header.utime. Empty origin: none.
  struct LatencyProbe {
    std::string name;            // counter prefix on STATUS
    std::string origin_channel;  // received for its header only (the process subscribes to it)
    std::string output_port;
  };
  virtual LatencyProbe latencyProbe() const { return {}; }
  // A short word for STATUS ("running", "behind", ...); subclasses may refine it.
  virtual std::string state() const { return "running"; }
  // CPU time (ms) of the threads working for this stage beside the one that calls it (search threads, the
  // loop closer's worker), counted on STATUS as helper_cpu_ms after every input; negative: the stage has none.
  // Monitoring only, like the stage's own CPU time.
  virtual double helperCpuMs() const { return -1.0; }

  // Where this run's files go (products, checkpoints); called once before the first input. Live processes
  // pass RunFolder::live = true: a stage may then resume from its checkpoint and save on stop (onRunFolder).
  // A process that `adit launch` restarted says so on STATUS (counter `restarted`) whatever it recovers: an
  // operator must see the crash even when everything before it was lost.
  void useRunFolder(const RunFolder& folder) {
    if (folder.live && folder.restart_count > 0) setCount("restarted", 1);
    onRunFolder(folder);
  }

  // Forward gaps in sensor time above this are counted as "time_jump" and reported to onTimeJump().
  void setMaxTimeGap(double seconds) { max_time_gap_us_ = static_cast<std::int64_t>(seconds * 1e6); }
  void setInputChecks(const InputChecks& checks) { checks_ = checks; }
  const InputChecks& inputChecks() const { return checks_; }
  // From now on obey only commands signed with this key (runtime/command_auth.hpp); a live process's
  // --command-key. Without a key every well-formed command is obeyed (replay, tests, a private bus).
  void requireSignedCommands(CommandKey key);

 protected:
  // Declare an input port. Handler is called with the decoded message, in arrival order.
  template <class Msg>
  void subscribe(const std::string& port, const std::string& default_channel, std::function<void(const Msg&)> handler,
                 InputKind kind = InputKind::Stream);
  // Declare an output port.
  void advertise(const std::string& port, const std::string& default_channel);
  // Encode and publish on a port; fills header.seq with the port's sequence number.
  template <class Msg>
  void publish(const std::string& port, Msg& msg);

  void count(const std::string& counter, std::int64_t n = 1) { health_.counters[counter] += n; }
  // For counters a stage keeps itself: report its current value.
  void setCount(const std::string& counter, std::int64_t value) { health_.counters[counter] = value; }
  // The run folder, for nodes that resume from or write into it (useRunFolder).
  virtual void onRunFolder(const RunFolder& /*folder*/) {}
  // Count an input that could not be used (errors) or was skipped (drops). One log line per burst: repeats of
  // the same counter are logged as one summary line once an input is accepted again.
  void reportError(const std::string& counter, const std::string& message);
  void reportDrop(const std::string& counter, const std::string& message);

  // Called after a forward time gap on `port`, before the message is handled: reset temporal state.
  virtual void onTimeJump(const std::string& /*port*/) {}
  // True when a command that arrived on `port` may be obeyed: always without a key, else only when signed
  // (a refusal is counted as command_unsigned / command_bad_mac / command_replayed / command_stale). The
  // clock window is the one wall-clock read of a node, and only with a key, which replay never has.
  bool commandAuthentic(const std::string& port, const adit::command_t& command);
  virtual void onFinish() {}

 private:
  void countHelperCpu();  // helper_cpu_ms from helperCpuMs()

  // A decoded, valid message waiting for its time to be confirmed.
  struct Held {
    std::int64_t utime = 0;
    std::int64_t seq = -1;
    std::function<void()> run;
  };
  struct Input {
    std::string port;
    std::function<void(const std::uint8_t*, std::size_t)> handle;
    InputKind kind = InputKind::Stream;
    std::int64_t last_utime = -1;
    std::int64_t last_seq = -1;
    std::vector<Held> held;  // messages that do not continue the stream's time, oldest first
    std::vector<std::int64_t> recent_steps;  // last accepted forward steps (us), oldest first
    std::int64_t typicalStep() const;        // their median; 0 until a few are known
  };
  // Steps 1 and 3 of the input checks; false (counted) when the message must be skipped.
  bool wireOk(const std::string& port, const msg::WireCheck& check, std::size_t size);
  bool valuesOk(const std::string& port, const msg::Validation& invalid);
  // Step 4: runs `run` now, holds it, or drops it (counted); may also run messages held before.
  void admit(Input& input, Held message);
  bool continuesStream(const Input& input, std::int64_t utime) const;
  void dropHeld(Input& input);
  void accept(Input& input, Held& message);
  void countSequence(Input& input, std::int64_t seq);
  void emit(const std::string& port, Bytes bytes, std::int64_t utime);
  void endBursts();

  std::string name_;
  std::map<std::string, std::string> channels_;  // port -> channel
  std::map<std::string, Input> inputs_;          // port -> input
  std::string primary_port_;                     // the first port subscribed: what timing() measures
  std::map<std::string, std::int64_t> seq_;      // output port -> next sequence number
  Health health_;
  TimingWindow timing_;
  TimingWindow cpu_timing_;
  double wall_ms_total_ = 0, cpu_ms_total_ = 0;
  Sink* sink_ = nullptr;  // valid during deliver()/finish()
  std::int64_t max_time_gap_us_ = 1'000'000;
  InputChecks checks_;
  std::int64_t newest_utime_ = -1;                 // newest accepted stamp on any Stream input (the sensor clock)
  std::map<std::string, std::int64_t> bursts_;     // counter -> repeats not logged yet
  std::unique_ptr<CommandGate> command_gate_;      // set when commands must be signed
};

template <class Msg>
void Node::subscribe(const std::string& port, const std::string& default_channel,
                     std::function<void(const Msg&)> handler, InputKind kind) {
  channels_.emplace(port, default_channel);
  if (primary_port_.empty()) primary_port_ = port;
  Input input;
  input.port = port;
  input.kind = kind;
  input.handle = [this, port, handler = std::move(handler)](const std::uint8_t* data, std::size_t size) {
    if (!wireOk(port, msg::checkWire<Msg>(data, size, checks_.wire), size)) return;
    auto msg = std::make_shared<Msg>();
    int used = -1;
    try {
      used = msg->decode(data, 0, static_cast<int>(size));
    } catch (const std::exception&) {
      used = -1;  // the wire check makes this unreachable; kept so a decoder surprise is still only counted
    }
    if (used < 0) {
      reportError("decode_error", "undecodable message on " + channels_.at(port) + " (" + std::to_string(size) +
                                      " bytes): skipped");
      return;
    }
    using msg::validate;  // unqualified: wrapper types (msg::SweepMessage) bring their own overload by ADL
    if (!valuesOk(port, validate(*msg, checks_.values))) return;
    admit(inputs_.at(port), Held{msg->header.utime, msg->header.seq, [handler, msg] { handler(*msg); }});
  };
  inputs_[port] = std::move(input);
}

template <class Msg>
void Node::publish(const std::string& port, Msg& message) {
  message.header.seq = seq_[port]++;
  emit(port, msg::encode(message), message.header.utime);
}

}  // namespace adit::runtime
