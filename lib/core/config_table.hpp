// Declarative configuration: one table per stage config struct, one line per key, from which reading,
// validation, defaults and `adit config`'s documentation all come.
//
//   ConfigTable<LoamConfig> t("features.loam");
//   t.add("half_window", &LoamConfig::half_window, between(1, 50), "", "neighbours each side in the smoothness sum");
//
// - The default is the struct's own default member initialiser (or the `base` passed to read()).
// - read(config) sets every field whose key the config has, after checking its type and range; a bad value
//   throws ConfigError naming the key, the value, its file and the allowed range. Keys absent keep the base.
// - describe(struct) lists every key with the value in force, the default, type, range, unit and doc.
// - nest(&Outer::inner, innerTable) folds a sub-struct's table into the outer one.
//
// Adding a key (or converting one read today with `config.get<T>("stage.node.k", d)`): give the struct a
// field with the default as its initialiser, and add one line to that struct's table:
//   .add("k", &Struct::k, atLeast(0.0), "s", "one-line doc")
// Node-level keys (`*.node.*`) live in lib/nodes/node_config.hpp. The key is then known to the pipeline
// (an unknown key is an error at load), printed by `adit config` and checked by tests/nodes; run
// scripts/update-config.sh to regenerate launch/config/pipeline.yaml.
#pragma once

#include "core/config.hpp"

#include <Eigen/Core>

#include <cmath>
#include <cstdint>
#include <type_traits>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace adit {

// Allowed values: a numeric interval (each end closed or open, or unbounded) or a set of words.
struct ConfigRange {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;
  std::vector<std::string> choices;  // text keys: the allowed words (empty: any)

  bool contains(double v) const {
    return std::isfinite(v) && (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  bool allows(const std::string& word) const;
  std::string text() const;  // "> 0", ">= 1 and <= 50", "one of huber, cauchy, none", "any"
};

inline ConfigRange anyValue() { return {}; }
inline ConfigRange atLeast(double lo) { ConfigRange r; r.lo = lo; return r; }
inline ConfigRange above(double lo) { ConfigRange r; r.lo = lo; r.lo_open = true; return r; }
inline ConfigRange between(double lo, double hi) { ConfigRange r; r.lo = lo; r.hi = hi; return r; }
inline ConfigRange aboveUpTo(double lo, double hi) { ConfigRange r = between(lo, hi); r.lo_open = true; return r; }
inline ConfigRange oneOf(std::vector<std::string> words) { ConfigRange r; r.choices = std::move(words); return r; }

// One key as documented and in force, for `adit config`, the schema and tests.
struct ConfigKeyInfo {
  std::string key, value, default_value, type, unit, doc;
  ConfigRange range;
  bool integer = false;  // numeric keys: whole numbers only
  bool numeric = false;
  bool list = false;     // a YAML sequence (key.0, key.1, ...)
};

namespace config_detail {

template <class T> struct Kind;
template <> struct Kind<int> { static constexpr const char* name = "integer"; static constexpr bool integer = true; };
template <> struct Kind<std::uint32_t> { static constexpr const char* name = "integer"; static constexpr bool integer = true; };
template <> struct Kind<double> { static constexpr const char* name = "real"; static constexpr bool integer = false; };
template <> struct Kind<float> { static constexpr const char* name = "real"; static constexpr bool integer = false; };

[[noreturn]] void fail(const Config& c, const std::string& key, const std::string& value, const std::string& what,
                       const std::string& allowed);

template <class T>
T readNumber(const Config& c, const std::string& key, const std::string& text, const ConfigRange& range) {
  const std::string allowed = std::string(Kind<T>::name) + " " + range.text();
  T value{};
  try {
    value = Config::parse<T>(key, text);
  } catch (const std::runtime_error&) {
    fail(c, key, text, std::string("is not ") + (Kind<T>::integer ? "an integer" : "a number"), allowed);
  }
  ConfigRange bounds = range;  // a float field is compared with its bounds as floats (0.01f < 0.01)
  if constexpr (std::is_same_v<T, float>) bounds.lo = static_cast<float>(bounds.lo), bounds.hi = static_cast<float>(bounds.hi);
  if (!bounds.contains(static_cast<double>(value))) fail(c, key, text, "is out of range", allowed);
  return value;
}

template <class T>
void readScalar(const Config& c, const std::string& key, const ConfigRange& range, T& out) {
  if (c.has(key + ".0")) fail(c, key, "[...]", "is a list, a single value is expected", range.text());
  if (!c.has(key)) return;
  const std::string& text = c.values().at(key);
  if constexpr (std::is_same_v<T, bool>) {
    try {
      out = Config::parse<bool>(key, text);
    } catch (const std::runtime_error&) {
      fail(c, key, text, "is not a boolean", "true or false");
    }
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (!range.allows(text)) fail(c, key, text, "is not allowed", range.text());
    out = text;
  } else {
    out = readNumber<T>(c, key, text, range);
  }
}

// Elements of the YAML sequence at key (empty when the key is absent); a scalar there is an error.
std::vector<double> readList(const Config& c, const std::string& key, const ConfigRange& range, std::size_t size);

template <class T>
std::string formatValue(const T& v) {
  if constexpr (std::is_same_v<T, Eigen::Vector3f>) {
    return "[" + Config::format(v.x()) + ", " + Config::format(v.y()) + ", " + Config::format(v.z()) + "]";
  } else {
    return Config::format(v);
  }
}

}  // namespace config_detail

template <class S>
struct ConfigField {
  ConfigKeyInfo info;                                       // value empty: filled by describe()
  std::function<void(const Config&, S&)> read;              // validates and sets the field if the key is given
  std::function<std::string(const S&)> format;              // the field's value as YAML text
};

template <class S>
class ConfigTable {
 public:
  explicit ConfigTable(std::string prefix) : prefix_(std::move(prefix)) {}

  // A scalar (int, uint32, float, double, bool, string) or a 3-vector ([x, y, z]) field.
  template <class T>
  ConfigTable& add(const std::string& name, T S::*member, ConfigRange range, const std::string& unit,
                   const std::string& doc) {
    ConfigField<S> f;
    f.info.key = prefix_ + "." + name;
    f.info.unit = unit;
    f.info.doc = doc;
    f.info.range = range;
    const std::string key = f.info.key;
    if constexpr (std::is_same_v<T, Eigen::Vector3f>) {
      f.info.type = "list of 3 reals";
      f.info.numeric = f.info.list = true;
      f.read = [key, range, member](const Config& c, S& s) {
        const std::vector<double> v = config_detail::readList(c, key, range, 3);
        if (!v.empty()) s.*member = Eigen::Vector3d(v[0], v[1], v[2]).cast<float>();
      };
    } else {
      if constexpr (std::is_same_v<T, bool>) {
        f.info.type = "boolean";
      } else if constexpr (std::is_same_v<T, std::string>) {
        f.info.type = "text";
      } else {
        f.info.type = config_detail::Kind<T>::name;
        f.info.numeric = true;
        f.info.integer = config_detail::Kind<T>::integer;
      }
      f.read = [key, range, member](const Config& c, S& s) { config_detail::readScalar(c, key, range, s.*member); };
    }
    f.format = [member](const S& s) { return config_detail::formatValue(s.*member); };
    f.info.default_value = f.format(S{});
    fields_.push_back(std::move(f));
    return *this;
  }

  // Folds the fields of a sub-struct's table (keys kept as that table names them). The defaults are the outer
  // struct's: its member may start from other values than the sub-struct's own defaults.
  template <class Sub>
  ConfigTable& nest(Sub S::*member, const ConfigTable<Sub>& sub) {
    for (const ConfigField<Sub>& g : sub.fields()) {
      ConfigField<S> f;
      f.info = g.info;
      f.read = [member, read = g.read](const Config& c, S& s) { read(c, s.*member); };
      f.format = [member, format = g.format](const S& s) { return format(s.*member); };
      f.info.default_value = f.format(S{});
      fields_.push_back(std::move(f));
    }
    return *this;
  }

  // The struct with every key the config gives applied over `base` (validated; throws ConfigError).
  S read(const Config& c, S base = S{}) const {
    for (const auto& f : fields_) f.read(c, base);
    return base;
  }

  // Every key with the value it has in `s`.
  std::vector<ConfigKeyInfo> describe(const S& s) const {
    std::vector<ConfigKeyInfo> out;
    for (const auto& f : fields_) {
      out.push_back(f.info);
      out.back().value = f.format(s);
    }
    return out;
  }

  const std::vector<ConfigField<S>>& fields() const { return fields_; }
  const std::string& prefix() const { return prefix_; }

 private:
  std::string prefix_;
  std::vector<ConfigField<S>> fields_;
};

}  // namespace adit

namespace adit {

// Checks that every key of `c` is known: either one of `known` (list elements key.N folded into key) or in
// a top-level section of `foreign_sections`, read by other code. Throws ConfigError naming the first
// unknown key, its file and the nearest known key.
void checkKnownKeys(const Config& c, const std::vector<ConfigKeyInfo>& known,
                    const std::vector<std::string>& foreign_sections);

// The known key nearest to `key` (edit distance), for "did you mean".
std::string nearestKey(const std::string& key, const std::vector<std::string>& candidates);

}  // namespace adit
