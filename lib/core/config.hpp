// Configuration as a flat, ordered map of dotted keys ("odometry.max_iterations" -> "10"), read from YAML.
// Stages take plain config structs; nodes fill them from a Config with documented defaults.
#pragma once

#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace adit {

// A configuration file or value that cannot be used: the message names the key, the value, the file and
// what is allowed. Processes and `adit` exit with status 2 on it.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Config {
 public:
  Config() = default;
  // Throws std::runtime_error naming the file and the problem.
  static Config fromYamlFile(const std::string& path);
  static Config fromYamlString(const std::string& text);

  // Overlay: values of `other` replace ours (a sensor file over the pipeline defaults).
  void merge(const Config& other);

  bool has(const std::string& key) const { return values_.count(key) > 0; }
  // The file a key was read from ("" when set in code or from a string).
  std::string originOf(const std::string& key) const {
    auto it = origins_.find(key);
    return it == origins_.end() ? std::string() : it->second;
  }
  void set(const std::string& key, const std::string& value) {
    values_[key] = value;
    origins_.erase(key);
  }
  const std::map<std::string, std::string>& values() const { return values_; }

  // Typed read with a default; throws std::runtime_error if the value does not parse as T.
  template <class T>
  T get(const std::string& key, const T& fallback) const {
    auto it = values_.find(key);
    const T value = it == values_.end() ? fallback : parse<T>(key, it->second);
    if (reads_) (*reads_)[key] = format(value);
    return value;
  }
  // A YAML sequence ("key: [1, 2, 3]") stored as key.0, key.1, ...
  template <class T>
  std::vector<T> getList(const std::string& key, const std::vector<T>& fallback) const {
    std::vector<T> out = fallback;
    if (has(key + ".0")) {
      out.clear();
      for (int i = 0; has(key + "." + std::to_string(i)); ++i)
        out.push_back(parse<T>(key, values_.at(key + "." + std::to_string(i))));
    }
    if (reads_) {
      std::string text = "[";
      for (std::size_t i = 0; i < out.size(); ++i) text += (i ? ", " : "") + format(out[i]);
      (*reads_)[key] = text + "]";
    }
    return out;
  }

  // Record every key read through get()/getList() with the value it resolved to (the default when the key
  // is absent), for `adit config --defaults` and the check that launch/config files name only real keys.
  void recordReadsInto(std::map<std::string, std::string>* reads) const { reads_ = reads; }

  // Text -> T (throws std::runtime_error if it does not parse) and T -> text, as get() does.
  template <class T>
  static T parse(const std::string& key, const std::string& text) {
    if constexpr (std::is_same_v<T, std::string>) {
      return text;
    } else if constexpr (std::is_same_v<T, bool>) {
      if (text == "true" || text == "True" || text == "1" || text == "yes" || text == "on") return true;
      if (text == "false" || text == "False" || text == "0" || text == "no" || text == "off") return false;
      throw std::runtime_error("config: '" + key + "' = '" + text + "' is not a boolean");
    } else {
      if (std::is_unsigned_v<T> && text.find('-') != std::string::npos)
        throw std::runtime_error("config: '" + key + "' = '" + text + "' is not a valid number");
      std::istringstream in(text);
      T value{};
      in >> value;
      if (in.fail() || !(in >> std::ws).eof())
        throw std::runtime_error("config: '" + key + "' = '" + text + "' is not a valid number");
      return value;
    }
  }
  template <class T>
  static std::string format(const T& value) {
    if constexpr (std::is_same_v<T, std::string>) {
      return value;
    } else if constexpr (std::is_same_v<T, bool>) {
      return value ? "true" : "false";
    } else {
      std::ostringstream out;
      out << value;
      return out.str();
    }
  }

 private:
  std::map<std::string, std::string> values_;
  std::map<std::string, std::string> origins_;  // key -> file it came from
  mutable std::map<std::string, std::string>* reads_ = nullptr;  // not owned; null = not recording
};

}  // namespace adit
