// Starts the processes of a launch file, prefixes and captures their output (run_dir/<name>.log),
// restarts a crashed process with exponential back-off and gives up on one that keeps failing, records
// channels with lcm-logger, and stops everything cleanly (SIGINT, then SIGKILL after a timeout) on Ctrl-C, at
// the end of a duration, or when a process named in stop_when_exit ends.
//
// Every process started by the supervisor gets in its environment:
//   LCM_DEFAULT_URL     the launch file's lcm_url (when set)
//   ADIT_RUN_DIR        the run folder (logs, record*.lcmlog; where a stage keeps its checkpoints)
//   ADIT_PROCESS_NAME   its name in the launch file
//   ADIT_RESTART_COUNT  0 on the first start, n on the n-th restart: a stage that sees n > 0 knows it is
//                       resuming after a crash (reports "restarted" on STATUS, looks for its checkpoint)
//
// The recorder never overwrites: its first start writes record.lcmlog, each restart the next free name of
// record.1.lcmlog, record.2.lcmlog, ... (lcmlog frames concatenate, so `cat record*.lcmlog` in that order is
// one log).
#pragma once

#include "launch/launch_file.hpp"

#include <string>

namespace adit::launch {

struct SupervisorOptions {
  std::string run_dir;     // created; receives <process>.log and record.lcmlog
  std::string bin_dir;     // adit executables are taken from here first
  double duration_s = 0;   // 0 = until Ctrl-C or stop_when_exit
  bool echo = true;        // also print every child line, prefixed, on stdout
  double stop_timeout_s = 5.0;
};

// Exit codes of supervise() (and of `adit launch`).
enum : int {
  kRunOk = 0,           // ended as planned (duration, Ctrl-C, stop_when_exit with exit code 0)
  kRunCannotStart = 1,  // a process could not be started at all
  kRunFailed = 2,       // a process gave up (too many restarts), or failed and was not to be restarted, or a
                        // stop_when_exit process failed; the last line printed says which and why
};

int supervise(const LaunchSpec& spec, const SupervisorOptions& options);

// The first of run_dir/record.lcmlog, record.1.lcmlog, record.2.lcmlog, ... that does not exist.
std::string nextRecordPath(const std::string& run_dir);

}  // namespace adit::launch
