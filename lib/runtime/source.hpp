// Runs a message source (a bridge reading files, the live simulator): either writes every message to an
// LCM log as fast as it can, or publishes live over LCM paced by sensor time (times `rate`), with STATUS at
// 1 Hz and a clean stop on SIGINT/SIGTERM. One implementation for every source process.
#pragma once

#include "runtime/health.hpp"
#include "runtime/node.hpp"

#include <functional>
#include <string>

namespace adit::runtime {

struct OutgoingMessage {
  std::string channel;
  Bytes data;
  std::int64_t utime = 0;  // sensor time: paces live publishing and stamps log events
  // Live only: at the message's due time this is called instead of publishing `data` on LCM (the simulated
  // lidar's own UDP packets, `adit sim --lidar-udp`). A source that sets it cannot write a log.
  std::function<void()> send = nullptr;
};

class MessageSource {
 public:
  virtual ~MessageSource() = default;
  // Next message in time order; false at the end. Recoverable problems are counted in health().
  virtual bool next(OutgoingMessage& message) = 0;
  virtual const Health& health() const = 0;
  // Fraction of the input produced so far, or < 0 if unknown (a live sensor).
  virtual double progress() const { return -1.0; }

  // A source that waits for input (a live sensor) calls the hook about every 100 ms while nothing
  // arrives, so the runner keeps publishing STATUS while the sensor is silent.
  void setIdleHook(std::function<void()> hook) { idle_hook_ = std::move(hook); }

 protected:
  void idle() const {
    if (idle_hook_) idle_hook_();
  }

 private:
  std::function<void()> idle_hook_;
};

struct SourceRunOptions {
  std::string process;         // for STATUS and log lines, e.g. "lidar-bridge"
  std::string lcm_url;         // live publishing
  std::string output_log;      // if set: write a log instead of publishing
  std::string input;           // what is read (file or folder), for error messages
  double rate = 1.0;           // live: multiple of recorded speed (0 = as fast as possible)
  double status_period_s = 1.0;
  bool quiet = false;
  // Writing a log: skip (and count) unreadable inputs instead of stopping with no log written.
  bool keep_going = false;
};

// Returns the exit code (0 also when stopped by a signal).
int runSource(MessageSource& source, const SourceRunOptions& options);

}  // namespace adit::runtime
