// Starts the processes of a launch file, prefixes and captures their output (run_dir/<name>.log),
// restarts a crashed process with exponential back-off, records channels with lcm-logger, and stops
// everything cleanly (SIGINT, then SIGKILL after a timeout) on Ctrl-C, at the end of a duration, or when a
// process named in stop_when_exit ends.
#pragma once

#include "launch/launch_file.hpp"

namespace adit::launch {

struct SupervisorOptions {
  std::string run_dir;     // created; receives <process>.log and record.lcmlog
  std::string bin_dir;     // adit executables are taken from here first
  double duration_s = 0;   // 0 = until Ctrl-C or stop_when_exit
  bool echo = true;        // also print every child line, prefixed, on stdout
  double stop_timeout_s = 5.0;
};

// Returns 0 when the run ended as planned, 1 if a process could not be started at all.
int supervise(const LaunchSpec& spec, const SupervisorOptions& options);

}  // namespace adit::launch
