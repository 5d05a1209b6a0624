#include "io/imu_csv.hpp"

#include "io/limits.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>

namespace adit::io {
namespace {

constexpr double kNanosecondThreshold = 1e12;

std::string trim(const std::string& s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return "";
  const auto last = s.find_last_not_of(" \t\r\n");
  return s.substr(first, last - first + 1);
}

// Fields split on commas if the line has any, else on whitespace. Empty fields are kept (they are bad).
std::vector<std::string> splitFields(const std::string& line) {
  std::vector<std::string> fields;
  if (line.find(',') != std::string::npos) {
    std::size_t start = 0;
    while (true) {
      const auto comma = line.find(',', start);
      fields.push_back(trim(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  } else {
    std::size_t start = line.find_first_not_of(" \t\r");
    while (start != std::string::npos) {
      const auto end = line.find_first_of(" \t\r", start);
      fields.push_back(line.substr(start, end == std::string::npos ? std::string::npos : end - start));
      start = end == std::string::npos ? end : line.find_first_not_of(" \t\r", end);
    }
  }
  return fields;
}

bool parseDouble(const std::string& field, double& value) {
  if (field.empty()) return false;
  char* end = nullptr;
  value = std::strtod(field.c_str(), &end);
  return end != field.c_str() && *end == '\0' && std::isfinite(value);
}

bool startsWithNumber(const std::string& line) {
  const std::vector<std::string> fields = splitFields(line);
  double v = 0.0;
  return !fields.empty() && parseDouble(fields[0], v);
}

}  // namespace

ImuCsvConfig imuCsvConfigFrom(const Config& c) {
  ImuCsvConfig d;
  d.gyro_scale = c.get<double>("imu_csv.gyro_scale", d.gyro_scale);
  d.accel_scale = c.get<double>("imu_csv.accel_scale", d.accel_scale);
  d.mag_scale = c.get<double>("imu_csv.mag_scale", d.mag_scale);
  return d;
}

bool parseImuCsvLine(const std::string& line, const ImuCsvConfig& config, ImuSample& sample, std::string& reason) {
  const std::vector<std::string> fields = splitFields(line);
  if (fields.size() != 7 && fields.size() != 10) {
    reason = std::to_string(fields.size()) + " columns, expected 7 or 10";
    return false;
  }
  double v[10];
  for (std::size_t k = 0; k < fields.size(); ++k) {
    if (!parseDouble(fields[k], v[k])) {
      reason = "column " + std::to_string(k + 1) + " '" + fields[k] + "' is not a finite number";
      return false;
    }
  }
  if (v[0] < 0.0) {
    reason = "negative timestamp";
    return false;
  }
  if (v[0] > kMaxStampSeconds * 1e9) {  // even as nanoseconds: beyond the year 2286
    reason = "timestamp beyond the year 2286";
    return false;
  }
  sample = ImuSample{};
  // Nanoseconds: integer arithmetic would be exact, but a double holds epoch ns to ~0.25 us: enough for utime.
  sample.utime = v[0] > kNanosecondThreshold ? static_cast<std::int64_t>(std::llround(v[0] * 1e-3)) : toUtime(v[0]);
  sample.gyro = Eigen::Vector3d(v[1], v[2], v[3]) * config.gyro_scale;
  sample.accel = Eigen::Vector3d(v[4], v[5], v[6]) * config.accel_scale;
  if (fields.size() == 10) sample.magnetic_field = Eigen::Vector3d(v[7], v[8], v[9]) * config.mag_scale;
  return true;
}

std::string ImuCsvResult::badLineSummary(std::size_t max_listed) const {
  if (bad_lines.empty()) return "";
  std::string s = std::to_string(bad_lines.size()) + " bad line" + (bad_lines.size() == 1 ? "" : "s") + ": ";
  for (std::size_t k = 0; k < bad_lines.size() && k < max_listed; ++k) {
    if (k > 0) s += ", ";
    s += std::to_string(bad_lines[k].line_number) + " (" + bad_lines[k].reason + ")";
  }
  if (bad_lines.size() > max_listed) s += ", ...";
  return s;
}

ImuCsvResult readImuCsv(const std::string& path, const ImuCsvConfig& config) {
  std::ifstream in(path);
  if (!in) throw ReadError("IMU CSV: cannot open '" + path + "'");
  ImuCsvResult result;
  bool seen_data_line = false;
  std::string line;
  for (int line_number = 1; std::getline(in, line); ++line_number) {
    const std::string text = trim(line);
    if (text.empty() || text[0] == '#') {
      ++result.skipped_comments;
      continue;
    }
    if (!seen_data_line && !startsWithNumber(text)) {
      seen_data_line = true;
      result.had_header = true;
      continue;
    }
    seen_data_line = true;
    ImuSample sample;
    std::string reason;
    if (!parseImuCsvLine(text, config, sample, reason)) {
      result.bad_lines.push_back({line_number, reason});
      continue;
    }
    if (!result.samples.empty() && sample.utime < result.samples.back().utime) ++result.backwards_stamps;
    result.samples.push_back(sample);
  }
  if (in.bad()) throw ReadError("IMU CSV: read error in '" + path + "'");
  return result;
}

}  // namespace adit::io
