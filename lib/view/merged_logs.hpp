// The events of several LCM logs in time order (e.g. a sensor log and a replay's output.lcmlog): ties go
// to the earlier log, then each log's own order. Damage (corrupt frames, truncation) is counted per log.
#pragma once

#include "runtime/lcm_log.hpp"

#include <memory>
#include <string>
#include <vector>

namespace adit::view {

class MergedLogs {
 public:
  explicit MergedLogs(std::vector<std::string> paths);  // throws if a log cannot be opened
  bool next(runtime::LogEvent& out);
  // True when no log holds any event (before the first next()).
  bool empty() const;
  // One line per damaged log ("" lines are left out).
  std::vector<std::string> damage() const;

 private:
  std::vector<std::string> paths_;
  std::vector<std::unique_ptr<runtime::LogReader>> readers_;
  std::vector<runtime::LogEvent> heads_;
  std::vector<bool> live_;
};

}  // namespace adit::view
