#include "view/log_player.hpp"

#include "core/json_writer.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace adit::view {

LogPlayer::LogPlayer(std::vector<std::string> paths, double speed, bool playing)
    : paths_(std::move(paths)), speed_(speed), playing_(playing) {
  MergedLogs scan(paths_);
  runtime::LogEvent e;
  bool any = false;
  while (scan.next(e)) {
    if (!any) first_utime_ = e.timestamp;
    last_utime_ = std::max(last_utime_, e.timestamp);
    any = true;
  }
  if (!any) {
    std::string names;
    for (const auto& p : paths_) names += (names.empty() ? "'" : ", '") + p + "'";
    throw std::runtime_error(names + ": no LCM event (empty, or not an LCM log)");
  }
  logs_ = std::make_unique<MergedLogs>(paths_);
}

void LogPlayer::rewind(RunConsumer& session) {
  logs_ = std::make_unique<MergedLogs>(paths_);
  pending_valid_ = false;
  more_ = true;
  position_s_ = 0;
  session.reset();
}

void LogPlayer::feedTo(double position_s, RunConsumer& session) {
  position_s_ = std::clamp(position_s, 0.0, duration());
  const auto until = first_utime_ + static_cast<std::int64_t>(position_s_ * 1e6);
  while (more_) {
    if (!pending_valid_) {
      pending_valid_ = logs_->next(pending_);
      more_ = pending_valid_;
      if (!more_) break;
    }
    if (pending_.timestamp > until) break;
    session.apply(pending_.channel, pending_.data.data(), pending_.data.size(), pending_.timestamp);
    pending_valid_ = false;
  }
}

void LogPlayer::advance(double wall_dt_s, RunConsumer& session) {
  if (playing_) feedTo(position_s_ + wall_dt_s * speed_, session);
  if (position_s_ >= duration()) playing_ = false;
}

bool LogPlayer::command(const std::string& text, RunConsumer& session) {
  std::istringstream in(text);
  std::string verb;
  double value = 0;
  in >> verb;
  if (verb == "play") {
    if (atEnd()) rewind(session);
    playing_ = true;
  } else if (verb == "pause") {
    playing_ = false;
  } else if (verb == "speed" && (in >> value) && value >= 0.1 && value <= 50) {
    speed_ = value;
  } else if (verb == "seek" && (in >> value) && value >= 0) {
    if (value < position_s_) rewind(session);
    feedTo(value, session);
  } else {
    return false;
  }
  return true;
}

std::string LogPlayer::infoJson() const {
  JsonWriter j;
  j.key("log").beginObject().field("position_s", position_s_).field("duration_s", duration());
  j.field("playing", playing_).field("speed", speed_).endObject();
  return j.str();
}

}  // namespace adit::view
