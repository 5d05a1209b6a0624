#include "launch/launch_file.hpp"

#include <yaml-cpp/yaml.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <stdexcept>

namespace adit::launch {
namespace {

std::string substitute(const std::string& text, const std::map<std::string, std::string>& vars,
                       const std::string& where) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size()) {
    const std::size_t start = text.find("${", i);
    if (start == std::string::npos) {
      out += text.substr(i);
      break;
    }
    const std::size_t end = text.find('}', start);
    if (end == std::string::npos) throw std::runtime_error(where + ": unclosed ${ in '" + text + "'");
    out += text.substr(i, start - i);
    std::string name = text.substr(start + 2, end - start - 2);
    std::optional<std::string> fallback;  // ${VAR:-default}
    if (const auto dash = name.find(":-"); dash != std::string::npos) {
      fallback = name.substr(dash + 2);
      name.resize(dash);
    }
    if (auto it = vars.find(name); it != vars.end()) {
      out += it->second;
    } else if (const char* env = std::getenv(name.c_str())) {
      out += env;
    } else if (fallback) {
      out += *fallback;
    } else {
      throw std::runtime_error(where + ": variable ${" + name + "} is not set (pass --set " + name + "=...)");
    }
    i = end + 1;
  }
  return out;
}

Restart parseRestart(const std::string& s, const std::string& where) {
  if (s == "never") return Restart::Never;
  if (s == "on-failure") return Restart::OnFailure;
  if (s == "always") return Restart::Always;
  throw std::runtime_error(where + ": restart must be never, on-failure or always, not '" + s + "'");
}

// max_restarts and restart_window_s of `node` over `base`, checked.
RestartLimits readLimits(const YAML::Node& node, RestartLimits base, const std::string& where) {
  if (node["max_restarts"]) base.max_restarts = node["max_restarts"].as<int>();
  if (node["restart_window_s"]) base.window_s = node["restart_window_s"].as<double>();
  if (base.max_restarts < 0)
    throw std::runtime_error(where + ": max_restarts must be >= 0, not " + std::to_string(base.max_restarts));
  if (!(base.window_s > 0))
    throw std::runtime_error(where + ": restart_window_s must be > 0, not " + std::to_string(base.window_s));
  return base;
}

}  // namespace

namespace {

// `defaults:` gives variables a value where neither --set nor the environment does.
std::map<std::string, std::string> withDefaults(const YAML::Node& root, std::map<std::string, std::string> vars) {
  if (!root["defaults"]) return vars;
  if (!root["defaults"].IsMap()) throw std::runtime_error("'defaults' must be a map of VARIABLE: value");
  for (const auto& kv : root["defaults"]) {
    const std::string name = kv.first.as<std::string>();
    if (!vars.count(name) && !std::getenv(name.c_str())) vars[name] = kv.second.as<std::string>();
  }
  return vars;
}

// A process of the same name replaces the included one in place; others are appended.
void addProcess(LaunchSpec& spec, ProcessSpec proc) {
  for (ProcessSpec& existing : spec.processes)
    if (existing.name == proc.name) {
      existing = std::move(proc);
      return;
    }
  spec.processes.push_back(std::move(proc));
}

constexpr int kMaxIncludeDepth = 4;

LaunchSpec readLaunchFile(const std::string& path, const std::map<std::string, std::string>& given_vars, int depth) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error("launch file '" + path + "': " + e.what());
  }
  std::map<std::string, std::string> vars;
  try {
    vars = withDefaults(root, given_vars);
  } catch (const std::exception& e) {
    throw std::runtime_error("launch file '" + path + "': " + e.what());
  }
  const auto sub = [&](const YAML::Node& n, const std::string& field) { return substitute(n.as<std::string>(), vars, path + ": " + field); };
  // `include:` (a path relative to this file): start from that file's run, then change what this one says.
  LaunchSpec spec;
  spec.recorder_limits.max_restarts = 3;
  if (root["include"]) {
    if (depth >= kMaxIncludeDepth)
      throw std::runtime_error("launch file '" + path + "': includes nested deeper than " + std::to_string(kMaxIncludeDepth) + " (a cycle?)");
    const std::filesystem::path included = std::filesystem::path(path).parent_path() / sub(root["include"], "include");
    spec = readLaunchFile(included.string(), vars, depth + 1);
  }
  if (root["name"]) spec.name = sub(root["name"], "name");
  else if (spec.name.empty()) spec.name = "run";
  if (root["lcm_url"]) spec.lcm_url = sub(root["lcm_url"], "lcm_url");
  if (root["record"]) spec.record_channels = sub(root["record"], "record");
  if (root["grace_s"]) spec.grace_s = root["grace_s"].as<double>();
  spec.limits = readLimits(root, spec.limits, path);
  if (root["record_max_restarts"]) spec.recorder_limits.max_restarts = root["record_max_restarts"].as<int>();
  spec.recorder_limits.window_s = spec.limits.window_s;
  if (spec.recorder_limits.max_restarts < 0) throw std::runtime_error(path + ": record_max_restarts must be >= 0");
  if (root["stop_when_exit"])
    for (const auto& n : root["stop_when_exit"]) spec.stop_when_exit.push_back(n.as<std::string>());
  const bool has_processes = root["processes"] && root["processes"].IsSequence() && root["processes"].size() > 0;
  if (!has_processes && spec.processes.empty())
    throw std::runtime_error("launch file '" + path + "': needs a non-empty 'processes' list");
  if (root["processes"] && !root["processes"].IsSequence())
    throw std::runtime_error("launch file '" + path + "': 'processes' must be a list");
  const YAML::Node listed = has_processes ? root["processes"] : YAML::Node(YAML::NodeType::Sequence);
  for (const auto& p : listed) {
    ProcessSpec proc;
    if (!p["name"] || !p["command"] || !p["command"].IsSequence())
      throw std::runtime_error("launch file '" + path + "': every process needs 'name' and a 'command' list");
    proc.name = p["name"].as<std::string>();
    for (const auto& arg : p["command"]) proc.command.push_back(sub(arg, proc.name + ".command"));
    if (p["delay_s"]) proc.delay_s = p["delay_s"].as<double>();
    if (p["restart"]) proc.restart = parseRestart(p["restart"].as<std::string>(), path + ": " + proc.name);
    proc.limits = readLimits(p, spec.limits, path + ": " + proc.name);
    addProcess(spec, std::move(proc));
  }
  for (const auto& name : spec.stop_when_exit) {
    bool known = false;
    for (const auto& p : spec.processes) known = known || p.name == name;
    if (!known) throw std::runtime_error("launch file '" + path + "': stop_when_exit names unknown process '" + name + "'");
  }
  return spec;
}

}  // namespace

LaunchSpec loadLaunchFile(const std::string& path, const std::map<std::string, std::string>& vars) {
  try {
    return readLaunchFile(path, vars, 0);
  } catch (const YAML::Exception& e) {  // a value of the wrong type: name the file, not just the line
    throw std::runtime_error("launch file '" + path + "': " + e.what());
  }
}

}  // namespace adit::launch
