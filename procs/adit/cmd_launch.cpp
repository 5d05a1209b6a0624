// adit launch <launch_file> [--set VAR=VALUE ...] [--duration S]
#include "commands.hpp"

#include "launch/supervisor.hpp"

#include <ctime>
#include <filesystem>

namespace fs = std::filesystem;

namespace {

struct LaunchArgs {
  std::string file, log_dir;
  std::vector<std::string> sets;
  double duration_s = 0;
  bool quiet = false;
};

// The source tree when run from build/bin (so launch files can say ${ADIT_ROOT}/launch/...), else the cwd.
std::string aditRoot() {
  const fs::path root = fs::weakly_canonical(fs::path(executableDir()) / ".." / "..");
  return fs::exists(root / "launch") ? root.string() : fs::current_path().string();
}

std::string timestamp() {
  char buf[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", std::localtime(&now));
  return buf;
}

}  // namespace

void registerLaunchCommand(CLI::App& app) {
  auto args = std::make_shared<LaunchArgs>();
  auto* cmd = app.add_subcommand(
      "launch",
      "Start and supervise the processes of a launch file (README: Running the processes). Exit status 0: ended as "
      "planned; 1: a process could not be started; 2: a process gave up or failed (the last line says which)");
  cmd->add_option("launch_file", args->file, "Launch file, e.g. launch/sim.launch.yaml")->required()->check(CLI::ExistingFile);
  cmd->add_option("--set", args->sets, "Set a ${VAR} of the launch file: VAR=VALUE (repeatable)");
  cmd->add_option("--duration", args->duration_s, "Stop after this many seconds (default: Ctrl-C or the file's stop_when_exit)");
  cmd->add_option("--log-dir", args->log_dir, "Where run folders go (default: <adit>/logs)");
  cmd->add_flag("-q,--quiet", args->quiet, "Do not echo process output (it is still written to the run folder)");
  cmd->callback([args] {
    const std::string root = aditRoot();
    const std::string log_dir = args->log_dir.empty() ? (fs::path(root) / "logs").string() : args->log_dir;
    std::map<std::string, std::string> vars{{"ADIT_ROOT", root}, {"ADIT_BIN", executableDir()}};
    for (const auto& s : args->sets) {
      const auto eq = s.find('=');
      if (eq == std::string::npos || eq == 0) throw std::runtime_error("--set expects VAR=VALUE, got '" + s + "'");
      vars[s.substr(0, eq)] = s.substr(eq + 1);
    }
    // The run folder name needs the launch name, and the file may use ${RUN_DIR}: read the name first.
    vars["RUN_DIR"] = "";
    const auto probe = adit::launch::loadLaunchFile(args->file, vars);
    const std::string run_dir = (fs::path(log_dir) / (probe.name + "-" + timestamp())).string();
    vars["RUN_DIR"] = run_dir;
    const auto spec = adit::launch::loadLaunchFile(args->file, vars);

    adit::launch::SupervisorOptions options;
    options.run_dir = run_dir;
    options.bin_dir = executableDir();
    options.duration_s = args->duration_s;
    options.echo = !args->quiet;
    std::printf("[launch] %s: %zu process(es), output in %s\n", spec.name.c_str(), spec.processes.size(), run_dir.c_str());
    const int code = adit::launch::supervise(spec, options);
    if (code != 0) throw CLI::RuntimeError(code);
  });
}
