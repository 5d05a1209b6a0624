#include "runtime/source.hpp"

#include "runtime/lcm_log.hpp"
#include "runtime/process.hpp"
#include "runtime/status.hpp"

#include <lcm/lcm-cpp.hpp>
#include <spdlog/spdlog.h>

#include <chrono>
#include <stdexcept>
#include <thread>

namespace adit::runtime {
namespace {

// A log written from files is complete or not written at all: the first input that cannot be read stops
// the run (unless keep_going), and so does an input that yields nothing; the LogWriter then removes its
// temp file.
int writeLog(MessageSource& source, const SourceRunOptions& options) {
  LogWriter log(options.output_log);
  OutgoingMessage m;
  while (!stopRequested() && source.next(m)) {
    if (m.send) throw std::logic_error("a message sent by its own means (not on LCM) cannot be written to a log");
    if (source.health().errors > 0 && !options.keep_going) break;
    log.write(m.channel, m.data, m.utime);
  }
  const Health& h = source.health();
  if (h.errors > 0 && !options.keep_going) {
    spdlog::error("{} (no log written; --keep-going skips unreadable inputs)", h.last_error);
    return 1;
  }
  if (log.events() == 0 && !stopRequested()) {
    spdlog::error("'{}' holds no usable message: no log written to '{}'", options.input, options.output_log);
    return 1;
  }
  log.close();
  spdlog::info("wrote {} messages to {} ({} errors, {} skipped)", log.events(), options.output_log, h.errors, h.drops);
  return 0;
}

int publishLive(MessageSource& source, const SourceRunOptions& options) {
  lcm::LCM lcm(options.lcm_url);
  if (!lcm.good()) {
    spdlog::error("cannot open LCM '{}' (for udpm on one machine: ip route add 224.0.0.0/4 dev lo)", options.lcm_url);
    return 1;
  }
  using Clock = std::chrono::steady_clock;
  const std::string status_channel = statusChannel(options.process);
  const auto start = Clock::now();
  auto last_status = start;
  std::int64_t status_seq = 0, published = 0, published_at_last_status = 0;
  TimingWindow no_timing;
  PublishedTraffic traffic;
  const auto sendStatus = [&](const std::string& state) {
    const auto now = Clock::now();
    const double window = std::chrono::duration<double>(now - last_status).count();
    Health h = source.health();
    h.outputs = published;
    const double rate = window > 0 ? static_cast<double>(published - published_at_last_status) / window : 0.0;
    adit::status_t s = makeStatus(options.process, h, no_timing, wallUtime(), status_seq++,
                                  std::chrono::duration<double>(now - start).count(), rate, 0.0, state);
    traffic.report(s, window);
    const Bytes bytes = msg::encode(s);
    lcm.publish(status_channel, bytes.data(), static_cast<unsigned int>(bytes.size()));
    traffic.add(status_channel, bytes.size());
    last_status = now;
    published_at_last_status = published;
  };

  source.setIdleHook([&] {
    if (Clock::now() - last_status >= std::chrono::duration<double>(options.status_period_s)) sendStatus("waiting");
  });
  // Sensor time t maps to wall time: start + (t - t0) / rate.
  std::int64_t t0 = -1;
  OutgoingMessage m;
  sendStatus("starting");
  while (!stopRequested() && source.next(m)) {
    if (t0 < 0) t0 = m.utime;
    if (options.rate > 0) {
      const auto due = start + std::chrono::microseconds(static_cast<std::int64_t>(
                                   static_cast<double>(m.utime - t0) / options.rate));
      while (!stopRequested() && Clock::now() < due) {
        std::this_thread::sleep_until(std::min(due, Clock::now() + std::chrono::milliseconds(50)));
        if (Clock::now() - last_status >= std::chrono::duration<double>(options.status_period_s)) sendStatus("running");
      }
    }
    if (m.send) {
      m.send();
    } else {
      lcm.publish(m.channel, m.data.data(), static_cast<unsigned int>(m.data.size()));
      traffic.add(m.channel, m.data.size());
    }
    ++published;
    if (Clock::now() - last_status >= std::chrono::duration<double>(options.status_period_s)) sendStatus("running");
  }
  source.setIdleHook({});
  sendStatus("stopping");
  const Health& h = source.health();
  spdlog::info("published {} messages ({} errors, {} skipped)", published, h.errors, h.drops);
  return 0;
}

}  // namespace

int runSource(MessageSource& source, const SourceRunOptions& options) {
  installStopHandlers();
  try {
    return options.output_log.empty() ? publishLive(source, options) : writeLog(source, options);
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 1;
  }
}

}  // namespace adit::runtime
