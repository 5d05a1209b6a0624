#include "view/merged_logs.hpp"

#include <fmt/format.h>

namespace adit::view {

MergedLogs::MergedLogs(std::vector<std::string> paths) : paths_(std::move(paths)) {
  for (const auto& p : paths_) {
    readers_.push_back(std::make_unique<runtime::LogReader>(p));
    heads_.emplace_back();
    live_.push_back(readers_.back()->next(heads_.back()));
  }
}

bool MergedLogs::next(runtime::LogEvent& out) {
  int best = -1;
  for (std::size_t i = 0; i < readers_.size(); ++i)
    if (live_[i] && (best < 0 || heads_[i].timestamp < heads_[static_cast<std::size_t>(best)].timestamp))
      best = static_cast<int>(i);
  if (best < 0) return false;
  const auto b = static_cast<std::size_t>(best);
  out = std::move(heads_[b]);
  live_[b] = readers_[b]->next(heads_[b]);
  return true;
}

bool MergedLogs::empty() const {
  for (const bool live : live_)
    if (live) return false;
  return true;
}

std::vector<std::string> MergedLogs::damage() const {
  std::vector<std::string> lines;
  for (std::size_t i = 0; i < readers_.size(); ++i)
    if (readers_[i]->corruptFrames() || readers_[i]->truncated())
      lines.push_back(fmt::format("log '{}' is damaged: {} corrupt frame(s) skipped{}", paths_[i],
                                  readers_[i]->corruptFrames(), readers_[i]->truncated() ? ", truncated" : ""));
  return lines;
}

}  // namespace adit::view
