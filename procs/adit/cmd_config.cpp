// adit config [--config FILE ...]: every configuration key the pipeline stages read, with the value in force
// (the built-in default unless a file sets it), as YAML, each with its doc, unit, range and default as a
// comment. `adit config > my.yaml` starts a configuration.
// adit config --check FILE ...: validates files (unknown keys, types, ranges) without running anything.
#include "commands.hpp"

#include "core/config.hpp"
#include "nodes/node_config.hpp"
#include "runtime/process.hpp"

#include <fmt/format.h>

namespace {

std::string comment(const adit::ConfigKeyInfo& k) {
  std::string text = k.doc;
  if (!k.unit.empty()) text += " [" + k.unit + "]";
  text += "; " + k.type;
  if (k.range.text() != "any") text += " " + k.range.text();
  if (k.value != k.default_value) text += "; default " + k.default_value;
  return text;
}

std::string yamlScalar(const std::string& value) {
  const bool quote = value.empty() || (value.front() != '[' && value.find_first_of(":#{}&*!|>'\"%@`") != std::string::npos);
  return quote ? "\"" + value + "\"" : value;
}

// Dotted keys (sorted) as nested YAML, each with its comment.
void printYaml(const std::vector<adit::ConfigKeyInfo>& keys) {
  std::vector<std::string> open;  // path of the mapping we are in
  for (const auto& k : keys) {
    std::vector<std::string> parts;
    std::size_t start = 0, dot;
    while ((dot = k.key.find('.', start)) != std::string::npos) {
      parts.push_back(k.key.substr(start, dot - start));
      start = dot + 1;
    }
    const std::string leaf = k.key.substr(start);
    std::size_t common = 0;
    while (common < open.size() && common < parts.size() && open[common] == parts[common]) ++common;
    open.resize(common);
    for (std::size_t i = common; i < parts.size(); ++i) {
      fmt::print("{}{}:\n", std::string(2 * i, ' '), parts[i]);
      open.push_back(parts[i]);
    }
    fmt::print("{}{}: {}  # {}\n", std::string(2 * parts.size(), ' '), leaf, yamlScalar(k.value), comment(k));
  }
}

int checkFiles(const std::vector<std::string>& files) {
  int bad = 0;
  for (const auto& file : files) {
    try {
      adit::nodes::validatePipelineConfig(adit::Config::fromYamlFile(file));
      fmt::print("{}: ok\n", file);
    } catch (const adit::ConfigError& e) {
      fmt::print(stderr, "{}: {}\n", file, e.what());
      ++bad;
    }
  }
  return bad;
}

}  // namespace

void registerConfigCommand(CLI::App& app) {
  auto files = std::make_shared<std::vector<std::string>>();
  auto check = std::make_shared<std::vector<std::string>>();
  auto* cmd = app.add_subcommand("config",
                                 "Print every pipeline configuration key with the value in force, its doc, unit and "
                                 "range, as YAML; or check files");
  cmd->add_option("--config", *files, "YAML files to apply over the defaults (repeatable)");
  cmd->add_option("--check", *check, "Only validate these files (unknown keys, types, ranges); exit 2 if any is bad");
  cmd->callback([files, check] {
    if (!check->empty()) {
      if (checkFiles(*check) > 0) throw adit::ConfigError("config: " + std::string(check->size() > 1 ? "some files are" : "the file is") + " not valid");
      return;
    }
    const adit::Config config = adit::runtime::loadConfig(*files);
    adit::nodes::validatePipelineConfig(config);
    printYaml(adit::nodes::pipelineConfigDescription(config));
  });
}
