// IMU samples from a text/CSV file, one sample per line:
//     t gx gy gz ax ay az [mx my mz]
// separated by commas or spaces/tabs (a comma-separated line may also have spaces around fields).
//  - t: seconds; a value above 1e12 is nanoseconds (1e12 s would be the year ~33700; 1e12 ns is only
//    1000 s, so epoch-ns stamps are always far above it while relative ns stamps shorter than 1000 s
//    are not supported: write those in seconds).
//  - gyro (rad/s), accel (m/s^2, specific force, +g up at rest), magnetometer (tesla) after the scales
//    of ImuCsvConfig are applied.
// Lines that are empty or start with '#' are skipped; so is a header: the first non-comment line if it
// does not start with a number. Any other line that does not parse (wrong column count, a non-number,
// NaN/inf, a negative time) is counted as bad with its line number and skipped: never fatal.
// Timestamps are kept in file order; going backwards is counted (not dropped): the caller reports it.
// A missing or unreadable file throws ReadError.
#pragma once

#include <string>
#include <vector>

#include "core/config.hpp"
#include "core/types.hpp"
#include "io/io_error.hpp"

namespace adit::io {

struct ImuCsvConfig {
  // Multiplies the gyro columns to get rad/s. 1 = file in rad/s; 0.017453292519943295 for deg/s.
  double gyro_scale = 1.0;
  // Multiplies the accel columns to get m/s^2. 1 = file in m/s^2; 9.80665 for g.
  double accel_scale = 1.0;
  // Multiplies the magnetometer columns to get tesla. 1e-6: 9-axis IMUs commonly report microtesla.
  double mag_scale = 1e-6;
};

// Keys (prefix "imu_csv."): gyro_scale, accel_scale, mag_scale; defaults as above.
ImuCsvConfig imuCsvConfigFrom(const Config& c);

struct ImuCsvBadLine {
  int line_number = 0;  // 1-based
  std::string reason;
};

struct ImuCsvResult {
  std::vector<ImuSample> samples;
  std::vector<ImuCsvBadLine> bad_lines;
  int skipped_comments = 0;    // empty and '#' lines
  bool had_header = false;
  int backwards_stamps = 0;    // samples whose utime is below the previous sample's

  // "N bad lines: 12 (wrong column count), 40 (not a number), ..." (first few), or "" if none.
  std::string badLineSummary(std::size_t max_listed = 5) const;
};

// Parses one data line into a sample; false (and `reason`) if the line is bad.
bool parseImuCsvLine(const std::string& line, const ImuCsvConfig& config, ImuSample& sample, std::string& reason);

// Reads a whole file. Throws ReadError only if the file cannot be opened/read.
ImuCsvResult readImuCsv(const std::string& path, const ImuCsvConfig& config = {});

}  // namespace adit::io
