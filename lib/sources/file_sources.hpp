// Message sources over recorded files, shared by adit-lidar-bridge, adit-imu-bridge and `adit import`.
// A file that cannot be read, or a sweep whose time does not advance, is counted and skipped with one
// log line; the rest of the data set still flows.
#pragma once

#include "io/pcd.hpp"
#include "runtime/source.hpp"

#include <memory>
#include <string>

namespace adit::sources {

// KITTI odometry layout: <dir> is sequences/NN (velodyne/*.bin, times.txt, calib.txt). num_beams: of the sensor
// that wrote it; 0 = detected from the first scan (io::detectBeamCount: 64 on KITTI itself; 64 when the first
// scan shows no clear fan or cannot be read).
std::unique_ptr<runtime::MessageSource> makeKittiSource(const std::string& sequence_dir, const std::string& channel,
                                                        int num_beams = 0);

// A folder of PCD files, one sweep each, sorted by name.
std::unique_ptr<runtime::MessageSource> makePcdSource(const std::string& folder, const io::PcdFolderConfig& config,
                                                      const std::string& channel);

// An IMU text file: `t gx gy gz ax ay az [mx my mz]` per line (see io/imu_csv.hpp).
std::unique_ptr<runtime::MessageSource> makeImuCsvSource(const std::string& path, const std::string& channel);

}  // namespace adit::sources
