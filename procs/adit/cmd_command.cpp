// adit command save_map [NAME]: asks the running map owner (the loop closer) to save the corrected map,
// trajectory and pose graph into its run folder, as NAME.pcd / NAME.tum / NAME.g2o (default map.pcd,
// trajectory.tum, pose_graph.g2o). The receiver checks the name again: anyone on the bus can publish.
#include "commands.hpp"
#include "msg/encode.hpp"
#include "runtime/run_folder.hpp"

#include <adit/command_t.hpp>
#include <lcm/lcm-cpp.hpp>
#include <spdlog/spdlog.h>

#include <chrono>
#include <stdexcept>
#include <vector>

namespace {

struct CommandArgs {
  std::string name;
  std::string lcm_url;
  std::string channel = "MAPPER_COMMAND";
};

void publishSaveMap(const CommandArgs& a) {
  if (!a.name.empty()) {
    const std::string problem = adit::runtime::plainFileNameProblem(a.name);
    if (!problem.empty()) throw std::runtime_error("save_map '" + a.name + "': " + problem);
  }
  lcm::LCM lcm(a.lcm_url);
  if (!lcm.good()) throw std::runtime_error("cannot open LCM '" + a.lcm_url + "'");
  adit::command_t c;
  c.header.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                       std::chrono::system_clock::now().time_since_epoch()).count();
  c.header.seq = 0;
  c.command = "save_map";
  c.argument = a.name;
  const std::vector<std::uint8_t> bytes = adit::msg::encode(c);
  if (lcm.publish(a.channel, bytes.data(), static_cast<unsigned int>(bytes.size())) != 0)
    throw std::runtime_error("cannot publish on " + a.channel);
  spdlog::info("sent save_map{} on {}", a.name.empty() ? "" : " " + a.name, a.channel);
}

}  // namespace

void registerCommandCommand(CLI::App& app) {
  auto a = std::make_shared<CommandArgs>();
  auto* cmd = app.add_subcommand("command", "Send a command to the running processes (save_map [NAME])");
  cmd->require_subcommand(1);
  auto* save = cmd->add_subcommand("save_map", "The map owner saves the corrected map, trajectory and pose graph into its run folder");
  save->add_option("name", a->name, "Plain file name (NAME.pcd, NAME.tum, NAME.g2o); default map.pcd, trajectory.tum, pose_graph.g2o");
  save->add_option("--lcm-url", a->lcm_url, "LCM provider (default: $LCM_DEFAULT_URL or udpm)");
  save->add_option("--channel", a->channel, "Command channel")->capture_default_str();
  save->callback([a] { publishSaveMap(*a); });
}
