// Launch files (launch/*.launch.yaml): which processes to start, with which LCM URL and configuration,
// what to record, when the run ends and how often a crashing process is restarted. The format is documented
// in README.md ("Running the processes").
#pragma once

#include "launch/restart_policy.hpp"

#include <map>
#include <string>
#include <vector>

namespace adit::launch {

enum class Restart { Never, OnFailure, Always };

struct ProcessSpec {
  std::string name;                  // prefix of its output lines and name of its log file
  std::vector<std::string> command;  // argv; "adit-*" and "adit" resolve to the build's bin/ first
  Restart restart = Restart::OnFailure;
  double delay_s = 0.0;  // wait this long before the first start (let subscribers come up first)
  // max_restarts / restart_window_s: the file's top-level values unless the process sets its own.
  RestartLimits limits;
};

struct LaunchSpec {
  std::string name;
  std::string lcm_url;                   // exported as LCM_DEFAULT_URL to every process
  std::vector<ProcessSpec> processes;    // started in this order, stopped in reverse
  std::string record_channels;           // regex for lcm-logger; "" = record nothing
  std::vector<std::string> stop_when_exit;  // the run ends when any of these exits by itself
  double grace_s = 2.0;                  // after such an exit, let the rest drain before stopping
  RestartLimits limits;                  // top-level max_restarts (5) and restart_window_s (60)
  RestartLimits recorder_limits;         // the recorder's: record_max_restarts (3), same window
};

// Reads a launch file, substituting ${VAR} (or ${VAR:-default}) from `vars` first, then the environment. Throws
// std::runtime_error naming the file and the problem (unknown variable, missing field, bad value).
LaunchSpec loadLaunchFile(const std::string& path, const std::map<std::string, std::string>& vars);

}  // namespace adit::launch
