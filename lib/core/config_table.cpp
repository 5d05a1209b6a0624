#include "core/config_table.hpp"

#include <algorithm>
#include <set>

namespace adit {
namespace {

std::string number(double v) { return Config::format(v); }

std::string inFile(const Config& c, const std::string& key) {
  const std::string file = c.originOf(key);
  return file.empty() ? std::string() : " in " + file;
}

std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// "a.b.3" -> "a.b" (a list element), else the key itself.
std::string foldListElement(const std::string& key) {
  const auto dot = key.rfind('.');
  if (dot == std::string::npos || dot + 1 == key.size()) return key;
  const bool digits = std::all_of(key.begin() + static_cast<long>(dot) + 1, key.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
  return digits ? key.substr(0, dot) : key;
}

}  // namespace

bool ConfigRange::allows(const std::string& word) const {
  return choices.empty() || std::find(choices.begin(), choices.end(), word) != choices.end();
}

std::string ConfigRange::text() const {
  if (!choices.empty()) {
    std::string out = "one of";
    for (std::size_t i = 0; i < choices.size(); ++i) out += (i ? ", " : " ") + choices[i];
    return out;
  }
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  std::string out;
  if (has_lo) out += (lo_open ? "> " : ">= ") + number(lo);
  if (has_lo && has_hi) out += " and ";
  if (has_hi) out += (hi_open ? "< " : "<= ") + number(hi);
  return out.empty() ? "any" : out;
}

namespace config_detail {

void fail(const Config& c, const std::string& key, const std::string& value, const std::string& what,
          const std::string& allowed) {
  throw ConfigError("config: " + key + ": " + value + inFile(c, key) + " " + what + " (allowed: " + allowed + ")");
}

std::vector<double> readList(const Config& c, const std::string& key, const ConfigRange& range, std::size_t size) {
  const std::string allowed = std::to_string(size) + " reals, each " + range.text();
  if (c.has(key)) fail(c, key, c.values().at(key), "is not a list", allowed);
  std::vector<double> out;
  for (std::size_t i = 0; c.has(key + "." + std::to_string(i)); ++i) {
    const std::string element = key + "." + std::to_string(i);
    out.push_back(readNumber<double>(c, element, c.values().at(element), range));
  }
  if (!out.empty() && out.size() != size)
    fail(c, key, "a list of " + std::to_string(out.size()), "has the wrong length", allowed);
  return out;
}

}  // namespace config_detail

std::string nearestKey(const std::string& key, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = std::string::npos;
  for (const auto& candidate : candidates) {
    const std::size_t d = editDistance(key, candidate);
    if (d < best_distance) best_distance = d, best = candidate;
  }
  return best;
}

void checkKnownKeys(const Config& c, const std::vector<ConfigKeyInfo>& known,
                    const std::vector<std::string>& foreign_sections) {
  std::set<std::string> keys;
  for (const auto& k : known) keys.insert(k.key);
  for (const auto& kv : c.values()) {
    const std::string key = foldListElement(kv.first);
    if (keys.count(key) || keys.count(kv.first)) continue;
    const std::string section = kv.first.substr(0, kv.first.find('.'));
    if (std::find(foreign_sections.begin(), foreign_sections.end(), section) != foreign_sections.end()) continue;
    std::vector<std::string> candidates(keys.begin(), keys.end());
    for (const auto& s : foreign_sections) candidates.push_back(s + ".*");
    throw ConfigError("config: unknown key '" + kv.first + "'" + inFile(c, kv.first) + "; did you mean '" +
                      nearestKey(kv.first, candidates) + "'? (`adit config` lists every key)");
  }
}

}  // namespace adit
