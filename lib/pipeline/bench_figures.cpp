#include "pipeline/bench_figures.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace adit::pipeline {

double helperCpuMs(const StageTiming& stage) {
  const auto it = stage.counters.find("helper_cpu_ms");
  return it == stage.counters.end() ? -1.0 : static_cast<double>(it->second);
}

std::vector<BenchFigure> benchFigures(const ReplayReport& r) {
  const double sweeps = r.sweeps > 0 ? static_cast<double>(r.sweeps) : 1.0;
  std::vector<BenchFigure> f;
  for (const StageTiming& t : r.timing) {
    f.push_back({t.stage + ".wall_median_ms", t.median_ms, "ms", false});
    f.push_back({t.stage + ".wall_p95_ms", t.p95_ms, "ms", false});
    f.push_back({t.stage + ".cpu_median_ms", t.cpu_median_ms, "ms", false});
    f.push_back({t.stage + ".cpu_ms_per_sweep", t.cpu_total_ms / sweeps, "ms", false});
    if (const double helpers = helperCpuMs(t); helpers >= 0)
      f.push_back({t.stage + ".helper_cpu_ms_per_sweep", helpers / sweeps, "ms", false});
  }
  f.push_back({"wall_ms_per_sweep", r.wall_seconds * 1e3 / sweeps, "ms", false});
  f.push_back({"process_cpu_ms_per_sweep", r.process_cpu_seconds * 1e3 / sweeps, "ms", false});
  f.push_back({"realtime_factor", r.wall_seconds > 0 ? r.sensor_seconds / r.wall_seconds : 0.0, "x", true});
  f.push_back({"peak_memory_mb", r.peak_memory_mb, "MB", false});
  return f;
}

namespace {

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += (static_cast<unsigned char>(c) < 0x20) ? ' ' : c;
  }
  return out + "\"";
}

}  // namespace

std::string benchFiguresJson(const std::vector<BenchFigure>& figures, const std::string& input) {
  std::string out = "{\n  \"input\": " + quoted(input) + ",\n  \"figures\": [";
  for (std::size_t i = 0; i < figures.size(); ++i) {
    const BenchFigure& f = figures[i];
    out += fmt::format("{}\n    {{\"name\": {}, \"value\": {:.4f}, \"unit\": {}, \"higher_is_better\": {}}}", i ? "," : "",
                       quoted(f.name), f.value, quoted(f.unit), f.higher_is_better ? "true" : "false");
  }
  return out + "\n  ]\n}\n";
}

std::vector<BenchFigure> readBenchFigures(const std::string& path) {
  std::vector<BenchFigure> figures;
  try {
    const YAML::Node root = YAML::LoadFile(path);  // JSON is YAML
    const YAML::Node list = root["figures"];
    if (!list || !list.IsSequence()) throw std::runtime_error("no \"figures\" list");
    for (const YAML::Node& n : list) {
      BenchFigure f;
      f.name = n["name"].as<std::string>();
      f.value = n["value"].as<double>();
      f.unit = n["unit"] ? n["unit"].as<std::string>() : "";
      f.higher_is_better = n["higher_is_better"] && n["higher_is_better"].as<bool>();
      if (!std::isfinite(f.value)) throw std::runtime_error("figure '" + f.name + "' is not a number");
      figures.push_back(f);
    }
  } catch (const std::exception& e) {
    throw std::runtime_error("'" + path + "' is not a benchmark file of adit bench pipeline --json: " + e.what());
  }
  return figures;
}

std::vector<FigureChange> compareFigures(const std::vector<BenchFigure>& before, const std::vector<BenchFigure>& after,
                                         double tolerance_pct) {
  const auto find = [](const std::vector<BenchFigure>& list, const std::string& name) -> const BenchFigure* {
    const auto it = std::find_if(list.begin(), list.end(), [&](const BenchFigure& f) { return f.name == name; });
    return it == list.end() ? nullptr : &*it;
  };
  std::vector<FigureChange> changes;
  for (const BenchFigure& a : before) {
    FigureChange c{a.name, a.unit, a.value, 0, 0, false, false};
    c.higher_is_better = a.higher_is_better;
    const BenchFigure* b = find(after, a.name);
    if (!b) {
      c.missing = true;
      changes.push_back(c);
      continue;
    }
    c.after = b->value;
    c.change_pct = a.value != 0 ? (b->value - a.value) / std::abs(a.value) * 100.0 : 0.0;
    c.change_min_pct = c.change_max_pct = c.change_pct;
    const double worse = a.higher_is_better ? -c.change_pct : c.change_pct;
    c.regression = worse > tolerance_pct;
    changes.push_back(c);
  }
  for (const BenchFigure& b : after)
    if (!find(before, b.name)) {
      FigureChange c{b.name, b.unit, 0, b.value, 0, false, true};
      c.higher_is_better = b.higher_is_better;
      changes.push_back(c);
    }
  return changes;
}

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

std::vector<FigureChange> compareFigurePairs(const std::vector<std::vector<BenchFigure>>& before,
                                             const std::vector<std::vector<BenchFigure>>& after, double tolerance_pct) {
  if (before.empty() || before.size() != after.size())
    throw std::invalid_argument(fmt::format("bench compare: {} run(s) before and {} after: pairs need as many of each",
                                            before.size(), after.size()));
  std::vector<std::vector<FigureChange>> pairs;
  for (std::size_t i = 0; i < before.size(); ++i) pairs.push_back(compareFigures(before[i], after[i], tolerance_pct));
  // Every figure any pair has, in the order the pairs first name them.
  std::vector<const FigureChange*> named;
  for (const auto& pair : pairs)
    for (const FigureChange& c : pair)
      if (std::none_of(named.begin(), named.end(), [&](const FigureChange* n) { return n->name == c.name; }))
        named.push_back(&c);
  std::vector<FigureChange> out;
  for (const FigureChange* first : named) {
    FigureChange c = *first;
    std::vector<double> befores, afters, changes;
    for (const auto& pair : pairs) {
      const auto it = std::find_if(pair.begin(), pair.end(), [&](const FigureChange& x) { return x.name == c.name; });
      if (it == pair.end() || it->missing) {
        c.missing = true;
        break;
      }
      befores.push_back(it->before);
      afters.push_back(it->after);
      changes.push_back(it->change_pct);
    }
    if (!c.missing) {
      c.before = median(befores);
      c.after = median(afters);
      c.change_pct = median(changes);
      c.change_min_pct = *std::min_element(changes.begin(), changes.end());
      c.change_max_pct = *std::max_element(changes.begin(), changes.end());
      const double worse = c.higher_is_better ? -c.change_pct : c.change_pct;
      c.regression = worse > tolerance_pct;
    }
    out.push_back(c);
  }
  return out;
}

}  // namespace adit::pipeline
