// adit command save_map [NAME]: asks the running map owner (the loop closer) to save the corrected map,
// trajectory and pose graph into its run folder, as NAME.pcd / NAME.tum / NAME.g2o (default map.pcd,
// trajectory.tum, pose_graph.g2o). The receiver checks the name again: anyone on the bus can publish.
// With a key (--key / $ADIT_COMMAND_KEY) the command is signed, for processes that obey only signed ones.
// adit command save_bundle [NAME]: the map owner writes a map bundle folder NAME (default map_bundle) into its
// run folder, for later runs' --prior-map.
// adit command set_pose X Y Z HEADING_DEG [--radius R]: tells the relocaliser (on RELOC_COMMAND) that the robot
// is within R m of that pose of the saved map now; it relocalises only there (a pillar grid's twins are far).
// adit command keygen FILE: writes a new random key (mode 0600, never over an existing file).
#include "commands.hpp"
#include "msg/encode.hpp"
#include "runtime/command_auth.hpp"
#include "runtime/command_message.hpp"
#include "runtime/process.hpp"
#include "runtime/run_folder.hpp"

#include <adit/command_t.hpp>
#include <lcm/lcm-cpp.hpp>
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <stdexcept>
#include <vector>

namespace {

struct CommandArgs {
  std::string command = "save_map";
  std::string name;
  std::string lcm_url;
  std::string channel = "MAPPER_COMMAND";
  std::string key_path;
  std::string new_key_path;
};

void publishSave(const CommandArgs& a) {
  if (!a.name.empty() && a.command != "set_pose") {
    const std::string problem = adit::runtime::plainFileNameProblem(a.name);
    if (!problem.empty()) throw std::runtime_error(a.command + " '" + a.name + "': " + problem);
  }
  lcm::LCM lcm(a.lcm_url);
  if (!lcm.good()) throw std::runtime_error("cannot open LCM '" + a.lcm_url + "'");
  const std::string key_path = adit::runtime::commandKeyPath(a.key_path);
  const adit::command_t c =
      adit::runtime::makeCommand(a.channel, a.command, a.name, key_path, adit::runtime::wallUtime());
  const std::vector<std::uint8_t> bytes = adit::msg::encode(c);
  if (lcm.publish(a.channel, bytes.data(), static_cast<unsigned int>(bytes.size())) != 0)
    throw std::runtime_error("cannot publish on " + a.channel);
  spdlog::info("sent {}{}{} on {}", key_path.empty() ? "" : "signed ", a.command, a.name.empty() ? "" : " " + a.name,
               a.channel);
}

}  // namespace

void registerCommandCommand(CLI::App& app) {
  auto a = std::make_shared<CommandArgs>();
  auto* cmd = app.add_subcommand("command", "Send a command to the running processes (save_map [NAME], save_bundle [NAME], set_pose X Y Z HEADING), or make a key");
  cmd->require_subcommand(1);
  auto* save = cmd->add_subcommand("save_map", "The map owner saves the corrected map, trajectory and pose graph into its run folder");
  save->add_option("name", a->name, "Plain file name (NAME.pcd, NAME.tum, NAME.g2o); default map.pcd, trajectory.tum, pose_graph.g2o");
  save->add_option("--lcm-url", a->lcm_url, "LCM provider (default: $LCM_DEFAULT_URL or udpm)");
  save->add_option("--channel", a->channel, "Command channel")->capture_default_str();
  save->add_option("--key", a->key_path, "Sign with this key file (default: $ADIT_COMMAND_KEY, else unsigned)");
  save->callback([a] { publishSave(*a); });
  auto* bundle = cmd->add_subcommand("save_bundle", "The map owner saves a map bundle folder into its run folder (for --prior-map)");
  bundle->add_option("name", a->name, "Plain folder name (default map_bundle)");
  bundle->add_option("--lcm-url", a->lcm_url, "LCM provider (default: $LCM_DEFAULT_URL or udpm)");
  bundle->add_option("--channel", a->channel, "Command channel")->capture_default_str();
  bundle->add_option("--key", a->key_path, "Sign with this key file (default: $ADIT_COMMAND_KEY, else unsigned)");
  bundle->callback([a] {
    a->command = "save_bundle";
    publishSave(*a);
  });
  auto pose = std::make_shared<std::vector<double>>();
  auto radius = std::make_shared<double>(0.0);
  auto* set_pose = cmd->add_subcommand("set_pose", "Tell the relocaliser the robot is near this pose of the saved map (X Y Z in m, heading in deg)");
  set_pose->add_option("pose", *pose, "X Y Z HEADING_DEG")->required()->expected(4);
  set_pose->add_option("--radius", *radius, "How far from it the robot may be, m (default: the relocaliser's reloc.start.radius)")
      ->check(CLI::PositiveNumber);
  set_pose->add_option("--lcm-url", a->lcm_url, "LCM provider (default: $LCM_DEFAULT_URL or udpm)");
  auto* pose_channel = set_pose->add_option("--channel", a->channel, "Command channel (default RELOC_COMMAND)");
  set_pose->add_option("--key", a->key_path, "Sign with this key file (default: $ADIT_COMMAND_KEY, else unsigned)");
  set_pose->callback([a, pose, radius, pose_channel] {
    a->command = "set_pose";
    if (pose_channel->count() == 0) a->channel = "RELOC_COMMAND";
    a->name = fmt::format("{} {} {} {}", (*pose)[0], (*pose)[1], (*pose)[2], (*pose)[3]);
    if (*radius > 0) a->name += fmt::format(" {}", *radius);
    publishSave(*a);
  });
  auto* keygen = cmd->add_subcommand("keygen", "Write a new random command key (hex, mode 0600) to FILE; never overwrites");
  keygen->add_option("file", a->new_key_path, "Where to write the key")->required();
  keygen->callback([a] {
    adit::runtime::writeNewCommandKey(a->new_key_path);
    spdlog::info("wrote a new command key to {} (give it to the processes with --command-key or $ADIT_COMMAND_KEY)",
                 a->new_key_path);
  });
}
