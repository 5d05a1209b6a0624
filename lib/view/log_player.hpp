// Plays recorded logs into a RunConsumer (adit view's sessions) at a chosen speed, for `adit view --log`: play, pause, speed and
// seek (the page's time slider). Seeking back replays from the start into a cleared session.
// Commands (text from the page): "play", "pause", "speed X" (0.1..50), "seek T" (seconds from the start).
#pragma once

#include "view/merged_logs.hpp"
#include "view/run_consumer.hpp"

#include <memory>
#include <string>
#include <vector>

namespace adit::view {

class LogPlayer {
 public:
  // Reads the logs once for their time span. Throws if one cannot be opened or none holds an event.
  LogPlayer(std::vector<std::string> paths, double speed, bool playing);

  // Moves the playback position on by wall_dt_s * speed (if playing) and feeds the events up to it.
  void advance(double wall_dt_s, RunConsumer& session);
  // A page command; false if it is not one of the playback commands.
  bool command(const std::string& text, RunConsumer& session);

  double position() const { return position_s_; }
  double duration() const { return static_cast<double>(last_utime_ - first_utime_) * 1e-6; }
  bool atEnd() const { return !pending_valid_ && !more_; }
  // "log":{...} members for the page's info frame.
  std::string infoJson() const;
  std::vector<std::string> damage() const { return logs_->damage(); }

 private:
  void rewind(RunConsumer& session);
  void feedTo(double position_s, RunConsumer& session);

  std::vector<std::string> paths_;
  std::unique_ptr<MergedLogs> logs_;
  runtime::LogEvent pending_;
  bool pending_valid_ = false, more_ = true;
  std::int64_t first_utime_ = 0, last_utime_ = 0;
  double position_s_ = 0, speed_ = 1;
  bool playing_ = true;
};

}  // namespace adit::view
