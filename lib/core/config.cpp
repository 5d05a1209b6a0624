#include "core/config.hpp"

#include <yaml-cpp/yaml.h>

namespace adit {
namespace {

void flatten(const YAML::Node& node, const std::string& prefix, std::map<std::string, std::string>& out) {
  const auto join = [&](const std::string& k) { return prefix.empty() ? k : prefix + "." + k; };
  switch (node.Type()) {
    case YAML::NodeType::Map:
      for (const auto& kv : node) flatten(kv.second, join(kv.first.as<std::string>()), out);
      break;
    case YAML::NodeType::Sequence:
      for (std::size_t i = 0; i < node.size(); ++i) flatten(node[i], join(std::to_string(i)), out);
      break;
    case YAML::NodeType::Scalar:
      out[prefix] = node.as<std::string>();
      break;
    default:
      break;  // null: leave the default in force
  }
}

}  // namespace

Config Config::fromYamlString(const std::string& text) {
  Config c;
  try {
    flatten(YAML::Load(text), "", c.values_);
  } catch (const YAML::Exception& e) {
    throw ConfigError(std::string("config: invalid YAML: ") + e.what());
  }
  return c;
}

Config Config::fromYamlFile(const std::string& path) {
  Config c;
  try {
    flatten(YAML::LoadFile(path), "", c.values_);
    for (const auto& kv : c.values_) c.origins_[kv.first] = path;
  } catch (const YAML::BadFile&) {
    throw ConfigError("config: cannot read '" + path + "'");
  } catch (const YAML::Exception& e) {
    throw ConfigError("config: invalid YAML in '" + path + "': " + e.what());
  }
  return c;
}

void Config::merge(const Config& other) {
  for (const auto& kv : other.values_) {
    values_[kv.first] = kv.second;
    const auto origin = other.origins_.find(kv.first);
    if (origin != other.origins_.end()) origins_[kv.first] = origin->second;
    else origins_.erase(kv.first);
  }
}

}  // namespace adit
