// adit config [--config FILE ...]: every configuration key the pipeline stages read, with the value in force
// (the built-in default unless a file sets it), as YAML. `adit config > my.yaml` starts a configuration.
#include "commands.hpp"

#include "core/config.hpp"
#include "nodes/registry.hpp"
#include "runtime/process.hpp"

#include <fmt/format.h>

namespace {

// Dotted keys (sorted) as nested YAML.
void printYaml(const std::map<std::string, std::string>& values) {
  std::vector<std::string> open;  // path of the mapping we are in
  for (const auto& [key, value] : values) {
    std::vector<std::string> parts;
    std::size_t start = 0, dot;
    while ((dot = key.find('.', start)) != std::string::npos) {
      parts.push_back(key.substr(start, dot - start));
      start = dot + 1;
    }
    const std::string leaf = key.substr(start);
    std::size_t common = 0;
    while (common < open.size() && common < parts.size() && open[common] == parts[common]) ++common;
    open.resize(common);
    for (std::size_t i = common; i < parts.size(); ++i) {
      fmt::print("{}{}:\n", std::string(2 * i, ' '), parts[i]);
      open.push_back(parts[i]);
    }
    const bool quote = value.empty() || value.find_first_of(":#{}&*!|>'\"%@`") != std::string::npos;
    fmt::print("{}{}: {}\n", std::string(2 * parts.size(), ' '), leaf, quote ? "\"" + value + "\"" : value);
  }
}

}  // namespace

void registerConfigCommand(CLI::App& app) {
  auto files = std::make_shared<std::vector<std::string>>();
  auto* cmd = app.add_subcommand("config", "Print every pipeline configuration key with the value in force, as YAML");
  cmd->add_option("--config", *files, "YAML files to apply over the defaults (repeatable)");
  cmd->callback([files] { printYaml(adit::nodes::pipelineConfigKeys(adit::runtime::loadConfig(*files))); });
}
