// Reader for the KITTI odometry layout:
//   <root>/sequences/NN/velodyne/XXXXXX.bin   float32 x, y, z, reflectance per point (16 bytes a point)
//   <root>/sequences/NN/times.txt             one timestamp (s) per scan, line k for XXXXXX = k
//   <root>/sequences/NN/calib.txt             P0..P3 and Tr (velodyne -> left camera), 3x4 row-major
//   <root>/poses/NN.txt                        ground truth: one 3x4 row-major LEFT CAMERA pose per line
//
// Timing (checked on kitti_mini): the HDL-64E spins counter-clockwise seen from above (azimuth
// atan2(y, x) increasing) at 10 Hz, and each sweep starts and ends facing backwards. The proof is the seam
// behind the car: ground points just left of straight back (azimuth -> +180 deg) lie ~0.9 m (00) to
// ~1.4 m (02) farther back than those just right of it (-> -180 deg), i.e. one scan's travel, so the
// +180 deg side is fired last. The front (0 deg) shows no seam. Hence, with azimuth a in (-pi, pi]:
//     dt = -(pi - a) / (2 pi) * 0.1 s      in [-0.1, 0]; -0.1 at -180 deg, -0.05 facing forward, 0 at +180.
// The scan's utime is the times.txt instant, as the adit time convention reads it (the last firing).
// Caution: KITTI's times.txt stamps are the camera trigger times, taken when the lidar faces forward,
// i.e. physically mid-sweep: the true last firing is ~50 ms after utime. Ground-truth poses refer to the
// times.txt instant too, so poses and scans share one time base; a consumer needing the physical
// instant must add 0.05 s. The scans are not motion-compensated (deskewed = false).
//
// Rings: KITTI stores points beam by beam, top beam first, each row sweeping from the front
// counter-clockwise once around; rings come from that scan order (see rings.hpp), ring 0 = lowest.
// If a file does not show exactly 64 rows (e.g. a cropped cloud), the nominal HDL-64E elevation table
// is used instead and the report says so (approximate: the real beams scatter by more than their spacing).
//
// Errors: a missing directory, velodyne folder, times.txt or scan file, a .bin whose size is not a
// multiple of 16 bytes, a times.txt or calib.txt that does not parse: ReadError naming the file.
// NaN points are kept for the preprocessing stage to count. Times going backwards are the caller's to report.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "io/io_error.hpp"

namespace adit::io {

constexpr double kKittiSweepDuration = 0.1;  // s, HDL-64E at 10 Hz
constexpr int kKittiNumBeams = 64;

struct KittiCalibration {
  std::array<Eigen::Matrix<double, 3, 4>, 4> P;             // camera projection matrices P0..P3
  Eigen::Isometry3d T_cam0_velo = Eigen::Isometry3d::Identity();  // Tr: velodyne -> left camera
};

enum class KittiRingMethod { kScanOrder, kNominalElevationTable, kElevationPeaks, kUniformFan };

// What scan() found besides the points (optional out-parameter).
struct KittiScanReport {
  KittiRingMethod ring_method = KittiRingMethod::kScanOrder;
  int nan_points = 0;  // points with a non-finite coordinate (kept)
};

// Per-point time relative to the sweep end for a KITTI point (see the header comment), in [-0.1, 0].
float kittiPointDt(float x, float y);

// A .bin above this is not a sweep (an HDL-64E sweep is ~2 MB): refused before anything is allocated.
constexpr std::uint64_t kKittiMaxScanBytes = 256ull << 20;

// Reads a KITTI velodyne .bin file as raw points (ring 0, dt 0). Throws ReadError naming the file when
// it is missing, empty, larger than kKittiMaxScanBytes or not a whole number of 16-byte points.
std::vector<LidarPoint> readKittiBin(const std::string& path);
// The same from bytes in memory; `name` is quoted in errors.
std::vector<LidarPoint> parseKittiBin(const std::uint8_t* bytes, std::size_t size, const std::string& name);

// times.txt: one time (s) per line, blank lines skipped. Throws ReadError naming `name`, the line and the
// problem (not a number, several numbers, negative, going backwards).
std::vector<double> parseKittiTimes(const std::string& text, const std::string& name);

// Reads calib.txt. Throws ReadError when it is missing, or P0..P3 / Tr are missing or malformed.
KittiCalibration readKittiCalibration(const std::string& path);

// Reads a KITTI poses file (3x4 row-major per line) as 4x4 transforms. Throws ReadError.
std::vector<Eigen::Isometry3d> readKittiPoses(const std::string& path);

class KittiSequence {
 public:
  // `path` is a sequence directory (<root>/sequences/NN) holding velodyne/ and times.txt.
  // calib.txt is read if present (needed only for ground truth). Throws ReadError.
  explicit KittiSequence(const std::string& path);
  // Same as KittiSequence(root + "/sequences/" + sequence), e.g. open(root, "00").
  static KittiSequence open(const std::string& root, const std::string& sequence);

  std::size_t size() const { return scan_files_.size(); }
  const std::string& directory() const { return directory_; }
  const std::vector<std::string>& scanFiles() const { return scan_files_; }  // sorted by name
  double timeSeconds(std::size_t i) const { return times_.at(i); }  // times.txt entry of scan i
  std::int64_t utime(std::size_t i) const { return toUtime(timeSeconds(i)); }
  bool hasCalibration() const { return has_calibration_; }
  const KittiCalibration& calibration() const;  // throws ReadError naming calib.txt if it was missing

  // Beams of the sensor that wrote the folder (KITTI: the HDL-64E's 64, the default). KITTI-layout folders
  // written from other heads (16, 32, 128 beams) set theirs, e.g. from detectBeamCount() of scan 0.
  // Throws std::invalid_argument unless 1..255.
  void setNumBeams(int num_beams);
  int numBeams() const { return num_beams_; }

  // Scan i: sensor "hdl64" with 64 beams (else "", unknown, with numBeams()), utime from times.txt, seq = i,
  // rings and dt set (see above). Rings with another beam count: by scan order if the file shows that many
  // rows, else by the scan's elevation peaks if there are that many, else a uniform fan over the scan's
  // elevation span.
  // Throws ReadError (bad index, missing or corrupt file).
  LidarScan scan(std::size_t i, KittiScanReport* report = nullptr) const;

  // Ground truth in the lidar frame: T_world_lidar_i = Tr^-1 * P_i * Tr, with P_i the camera pose of line i,
  // stamped with utime(i). The world frame is the lidar frame of scan 0 (P_0 = I in KITTI).
  // Line k of the poses file belongs to scan file k (000k.bin); extra lines are ignored. Throws ReadError.
  Trajectory groundTruthLidar(const std::string& poses_file) const;
  // <root>/poses/NN.txt for a sequence opened at <root>/sequences/NN.
  std::string defaultPosesFile() const;

 private:
  std::string directory_;
  std::vector<std::string> scan_files_;
  std::vector<double> times_;  // one per scan file, matched by the file's number
  bool has_calibration_ = false;
  KittiCalibration calibration_;
  int num_beams_ = kKittiNumBeams;
};

}  // namespace adit::io
