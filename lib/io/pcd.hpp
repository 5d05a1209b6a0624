// A folder of PCD files (one sweep each, sorted by file name) read as LidarScans, and a binary PCD writer.
// pcd_format.hpp parses ascii, binary and binary_compressed files and checks every size in the header
// against the bytes present (PCL's reader trusts the header; a crafted file crashed it).
//
// Fields: x, y, z required; intensity optional (else 0). `ring` optional, any integer or float type;
// numbered from the top beam (Ouster) it is renumbered so that 0 = lowest beam (orientRingsBottomUp).
// Per-point time optional, the first of `time`, `t`, `timestamp` present:
//   integer types are nanoseconds (Ouster `t`), float types are seconds (Velodyne `time`, Hesai/RoboSense
//   `timestamp`); values may be relative (to any origin) or absolute, since dt = value - (largest value),
//   which puts the last firing at dt = 0 as the adit convention wants. A time field whose values are all
//   equal carries no timing: has_time stays false.
// Without a ring field, rings come from the beam table of config.sensor (vlp16, rs16, hdl64) or else a
// uniform fan of config.num_beams beams between the configured elevations (rings.hpp). With neither,
// has_ring stays false.
//
// Scan utime, first rule that applies:
//  1. a double per-point time field with absolute values (> 1e6 s): the largest value (the last firing);
//  2. file names that are timestamps (checked for the whole folder: all or none): a name with a decimal
//     point is seconds ("1611234567.123456.pcd"); an all-digit name above 1e12 is nanoseconds
//     ("1611234567123456789.pcd"); anything else ("000042.pcd") is not a timestamp. The stamp is taken
//     as the sweep's end, or as its start if config.stamp_is_sweep_start (then utime = stamp + the
//     per-point time span, or + sweep_duration without times);
//  3. otherwise config.first_utime + index * sweep_duration.
//
// Errors: a missing folder, an unreadable/corrupt/truncated file, an ascii value that is not a number,
// missing x/y/z: ReadError naming the file (and the line, for header and ascii problems).
// NaN points are kept for the preprocessing stage to count.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/config.hpp"
#include "core/types.hpp"
#include "io/io_error.hpp"

namespace adit::io {

struct PcdFolderConfig {
  // Label for LidarScan::sensor, and the beam table for files without rings ("vlp16", "rs16", "hdl64").
  std::string sensor = "vlp16";
  // Beam count; 0 = take it from the ring field (max + 1) or the beam table. Needed for a uniform fan.
  int num_beams = 0;
  // Uniform fan (deg) used when the sensor has no known table and the files have no ring field.
  double min_elevation_deg = -15.0;
  double max_elevation_deg = 15.0;
  // Seconds per sweep: LidarScan::sweep_duration, and the utime spacing when names are not timestamps.
  // 0.1 s = the 10 Hz default of every spinning lidar we use.
  double sweep_duration = 0.1;
  // utime (us) of the first file when file names are not timestamps.
  std::int64_t first_utime = 0;
  // File-name stamps mark the sweep's start (Ouster, some recorders) instead of its end (Velodyne driver).
  bool stamp_is_sweep_start = false;
};

// Keys (prefix "pcd."): sensor, num_beams, min_elevation_deg, max_elevation_deg, sweep_duration,
// first_utime, stamp_is_sweep_start; defaults as above.
PcdFolderConfig pcdFolderConfigFrom(const Config& c);

// What reading one file found (optional out-parameter).
struct PcdScanReport {
  bool ring_field = false;     // rings came from the file
  bool rings_flipped = false;  // the field numbered beams from the top (Ouster): renumbered (rings.hpp)
  std::string time_field;      // "time", "t", "timestamp" or empty
  bool absolute_times = false;  // utime came from the per-point times (rule 1)
  int nan_points = 0;          // points with a non-finite coordinate (kept)
  int far_from_beam = 0;       // elevation-assigned points > 1 deg from their beam
  double time_max_seconds = 0.0;  // the largest per-point time (s) when the scan has times
};

// Reads one PCD file as a sweep with the given utime/seq (rule 1 may override utime). Throws ReadError.
LidarScan readPcdScan(const std::string& path, const PcdFolderConfig& config, std::int64_t utime, std::int64_t seq,
                      PcdScanReport* report = nullptr);

struct PcdCloud;
// The same conversion for a cloud already in memory (a ROS PointCloud2 shares PCD's field model);
// `name` starts error messages.
LidarScan scanFromCloud(const PcdCloud& cloud, const PcdFolderConfig& config, std::int64_t utime, std::int64_t seq,
                        const std::string& name, PcdScanReport* report = nullptr);

// The sweep time a file name encodes (rule 2 above), in utime; false if the name is not a timestamp.
bool pcdStampFromFileName(const std::string& path, std::int64_t& utime);

class PcdFolder {
 public:
  // Lists "*.pcd" in `folder` sorted by name. Throws ReadError if the folder does not exist.
  PcdFolder(const std::string& folder, const PcdFolderConfig& config);
  std::size_t size() const { return files_.size(); }
  const std::vector<std::string>& files() const { return files_; }
  bool namesAreTimestamps() const { return names_are_timestamps_; }
  // utime of file i by rule 2 or 3 (a sweep-start stamp not yet shifted; rule 1 only once read).
  std::int64_t nominalUtime(std::size_t i) const;
  // Sweep i (seq = i). Throws ReadError.
  LidarScan scan(std::size_t i, PcdScanReport* report = nullptr) const;

 private:
  PcdFolderConfig config_;
  std::vector<std::string> files_;
  std::vector<std::int64_t> stamps_;  // file-name stamps when names_are_timestamps_
  bool names_are_timestamps_ = false;
};

struct PcdWriteOptions {
  bool with_ring = false;  // add a uint16 `ring` field
  bool with_time = false;  // add a float32 `time` field holding dt (s, <= 0)
};

// Writes x, y, z, intensity (float32) [+ ring, time] as a binary PCD, atomically (atomic_file.hpp).
// Throws WriteError.
void writePcd(const std::string& path, const std::vector<LidarPoint>& points, const PcdWriteOptions& options = {});

}  // namespace adit::io
