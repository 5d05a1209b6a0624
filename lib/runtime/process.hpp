// Turns a Node into a process: flags, a live loop over LCM, STATUS at 1 Hz, clean shutdown on
// SIGINT/SIGTERM. With `--lcm-url file:///in.lcmlog?speed=0 --out-url file:///out.lcmlog?mode=w` the same
// process runs from a recording of its inputs to a log of its outputs.
#pragma once

#include "core/config.hpp"
#include "runtime/node.hpp"

#include <CLI/CLI.hpp>

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace adit::runtime {

struct ProcessOptions {
  std::string lcm_url;  // subscribe (and publish) here; "" = $LCM_DEFAULT_URL or LCM's default
  std::string out_url;  // publish here instead, if set
  std::vector<std::string> config_paths;  // merged in order: later files override earlier ones
  std::vector<std::string> config_sets;   // KEY=VALUE, over the files (a launch file's per-run setting)
  std::vector<std::string> channel_remaps;  // PORT=CHANNEL
  double status_period_s = 1.0;
  std::string status_channel;  // "" = STATUS_<NAME>
  std::string run_dir;  // "" = $ADIT_RUN_DIR, else "." (runtime/run_folder.hpp)
  std::string command_key;  // "" = $ADIT_COMMAND_KEY, else commands need no signature
};

// The command key file a process uses: flag_path, else $ADIT_COMMAND_KEY, else "" (none).
std::string commandKeyPath(const std::string& flag_path);

void addProcessOptions(CLI::App& app, ProcessOptions& options);

// Reads and merges --config files in order (none = built-in defaults). Throws std::runtime_error.
Config loadConfig(const std::vector<std::string>& paths);

// Sets each KEY=VALUE over `config`; throws std::runtime_error on a malformed one.
void applyConfigSets(Config& config, const std::vector<std::string>& sets);

// Applies PORT=CHANNEL remaps; throws std::runtime_error on a malformed one or an unknown port.
void applyRemaps(Node& node, const std::vector<std::string>& remaps);

using NodeFactory = std::function<std::unique_ptr<Node>(const Config&)>;

// The whole main() of a stage process. Returns the exit code.
int runNodeProcess(int argc, char** argv, const std::string& name, const std::string& description,
                   const NodeFactory& factory);

// Shared by every process: true once SIGINT or SIGTERM arrived (handlers installed on first call).
bool stopRequested();
void installStopHandlers();

// Wall-clock microseconds, for STATUS stamps only.
std::int64_t wallUtime();

}  // namespace adit::runtime
