#include "io/kitti.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "io/limits.hpp"
#include "io/rings.hpp"

namespace adit::io {
namespace fs = std::filesystem;
namespace {

// Parses all numbers of `text`; false if any token is not a number.
bool parseNumbers(const std::string& text, std::vector<double>& out) {
  std::istringstream in(text);
  std::string token;
  while (in >> token) {
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0' || !std::isfinite(v)) return false;
    out.push_back(v);
  }
  return true;
}

Eigen::Isometry3d isometryFrom3x4(const std::vector<double>& v) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = v[static_cast<size_t>(4 * r + c)];
  Eigen::Isometry3d T;
  T.matrix() = m;
  return T;
}

std::vector<double> readTimes(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ReadError("KITTI: cannot open times file '" + path + "'");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return parseKittiTimes(text, path);
}

// The scan number of "000042.bin" (42), or -1 if the name is not a plain number of at most 9 digits.
long scanNumber(const fs::path& file) {
  const std::string stem = file.stem().string();
  if (stem.empty() || stem.size() > 9 || !std::all_of(stem.begin(), stem.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return -1;
  return std::strtol(stem.c_str(), nullptr, 10);
}

}  // namespace

float kittiPointDt(float x, float y) {
  const double azimuth = std::atan2(static_cast<double>(y), static_cast<double>(x));  // (-pi, pi]
  const double dt = -(M_PI - azimuth) / (2.0 * M_PI) * kKittiSweepDuration;
  return static_cast<float>(std::clamp(dt, -kKittiSweepDuration, 0.0));
}

std::vector<double> parseKittiTimes(const std::string& text, const std::string& name) {
  std::vector<double> times;
  std::istringstream in(text);
  std::string line;
  for (int line_number = 1; std::getline(in, line); ++line_number) {
    std::vector<double> values;
    const auto where = [&] { return "KITTI: '" + name + "' line " + std::to_string(line_number) + ": "; };
    if (!parseNumbers(line, values))
      throw ReadError(where() + "'" + line.substr(0, 40) + "' is not a time in seconds");
    if (values.size() > 1) throw ReadError(where() + std::to_string(values.size()) + " numbers, expected one time in seconds");
    if (values.empty()) continue;
    if (values[0] < 0.0) throw ReadError(where() + "negative time " + std::to_string(values[0]));
    if (values[0] > kMaxStampSeconds)
      throw ReadError(where() + "time " + std::to_string(values[0]) + " s is beyond the year 2286");
    if (!times.empty() && values[0] < times.back())
      throw ReadError(where() + "time goes backwards (" + std::to_string(values[0]) + " after " +
                      std::to_string(times.back()) + ")");
    times.push_back(values[0]);
  }
  return times;
}

std::vector<LidarPoint> parseKittiBin(const std::uint8_t* bytes, std::size_t size, const std::string& name) {
  if (size == 0) throw ReadError("KITTI: scan '" + name + "' is empty (0 bytes)");
  if (size % 16 != 0)
    throw ReadError("KITTI: scan '" + name + "' is truncated or corrupt: " + std::to_string(size) +
                    " bytes is not a multiple of 16 (4 float32 per point)");
  std::vector<LidarPoint> points(size / 16);
  for (std::size_t i = 0; i < points.size(); ++i) {
    float v[4];
    std::memcpy(v, bytes + 16 * i, sizeof(v));
    points[i].p = Eigen::Vector3f(v[0], v[1], v[2]);
    points[i].intensity = v[3];
  }
  return points;
}

std::vector<LidarPoint> readKittiBin(const std::string& path) {
  std::error_code ec;
  const auto bytes = fs::file_size(path, ec);
  if (ec) throw ReadError("KITTI: cannot read scan '" + path + "': " + ec.message());
  if (bytes > kKittiMaxScanBytes)
    throw ReadError("KITTI: scan '" + path + "' is " + std::to_string(bytes) + " bytes, more than any sweep (limit " +
                    std::to_string(kKittiMaxScanBytes) + ")");
  std::ifstream in(path, std::ios::binary);
  std::vector<std::uint8_t> raw(static_cast<size_t>(bytes));
  if (!in || !in.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(bytes)))
    throw ReadError("KITTI: cannot read scan '" + path + "'");
  return parseKittiBin(raw.data(), raw.size(), path);
}

KittiCalibration readKittiCalibration(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ReadError("KITTI: cannot open calibration '" + path + "'");
  KittiCalibration calib;
  std::array<bool, 5> found{};  // P0..P3, Tr
  std::string line;
  for (int line_number = 1; std::getline(in, line); ++line_number) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(0, colon);
    const int slot = key == "Tr" ? 4 : (key.size() == 2 && key[0] == 'P' && key[1] >= '0' && key[1] <= '3') ? key[1] - '0' : -1;
    if (slot < 0) continue;  // other entries (Tr_imu_velo in raw data, ...) are not needed
    std::vector<double> v;
    if (!parseNumbers(line.substr(colon + 1), v) || v.size() != 12)
      throw ReadError("KITTI: '" + path + "' line " + std::to_string(line_number) + " (" + key +
                      ") does not hold 12 numbers");
    if (slot == 4) {
      calib.T_cam0_velo = isometryFrom3x4(v);
    } else {
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) calib.P[static_cast<size_t>(slot)](r, c) = v[static_cast<size_t>(4 * r + c)];
    }
    found[static_cast<size_t>(slot)] = true;
  }
  for (size_t s = 0; s < found.size(); ++s)
    if (!found[s]) throw ReadError("KITTI: '" + path + "' has no " + (s == 4 ? std::string("Tr") : "P" + std::to_string(s)));
  return calib;
}

std::vector<Eigen::Isometry3d> readKittiPoses(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ReadError("KITTI: cannot open poses file '" + path + "'");
  std::vector<Eigen::Isometry3d> poses;
  std::string line;
  for (int line_number = 1; std::getline(in, line); ++line_number) {
    std::vector<double> v;
    if (!parseNumbers(line, v) || (v.size() != 12 && !v.empty()))
      throw ReadError("KITTI: '" + path + "' line " + std::to_string(line_number) + " is not a 3x4 pose (12 numbers)");
    if (!v.empty()) poses.push_back(isometryFrom3x4(v));
  }
  return poses;
}

KittiSequence::KittiSequence(const std::string& path) : directory_(path) {
  const fs::path dir(path);
  if (!fs::is_directory(dir)) throw ReadError("KITTI: sequence directory '" + path + "' does not exist");
  const fs::path velodyne = dir / "velodyne";
  if (!fs::is_directory(velodyne)) throw ReadError("KITTI: scan folder '" + velodyne.string() + "' does not exist");
  for (const auto& entry : fs::directory_iterator(velodyne))
    if (entry.path().extension() == ".bin") scan_files_.push_back(entry.path().string());
  std::sort(scan_files_.begin(), scan_files_.end());

  const std::string times_path = (dir / "times.txt").string();
  if (!fs::exists(times_path)) throw ReadError("KITTI: times file '" + times_path + "' does not exist");
  const std::vector<double> all_times = readTimes(times_path);
  for (size_t i = 0; i < scan_files_.size(); ++i) {
    const long number = scanNumber(scan_files_[i]);
    const size_t line = number >= 0 ? static_cast<size_t>(number) : i;
    if (line >= all_times.size())
      throw ReadError("KITTI: '" + times_path + "' has " + std::to_string(all_times.size()) + " entries, none for scan '" +
                      scan_files_[i] + "'");
    times_.push_back(all_times[line]);
  }

  const std::string calib_path = (dir / "calib.txt").string();
  if (fs::exists(calib_path)) {
    calibration_ = readKittiCalibration(calib_path);
    has_calibration_ = true;
  }
}

KittiSequence KittiSequence::open(const std::string& root, const std::string& sequence) {
  return KittiSequence((fs::path(root) / "sequences" / sequence).string());
}

const KittiCalibration& KittiSequence::calibration() const {
  if (!has_calibration_)
    throw ReadError("KITTI: calibration '" + (fs::path(directory_) / "calib.txt").string() + "' does not exist");
  return calibration_;
}

namespace {

// Rings when the scan order does not show num_beams rows (see KittiSequence::scan).
KittiRingMethod assignRingsOtherwise(std::vector<LidarPoint>& points, int num_beams) {
  if (num_beams == kKittiNumBeams) {
    assignRingsByElevation(points, hdl64Elevations(), M_PI);
    return KittiRingMethod::kNominalElevationTable;
  }
  const std::vector<double> peaks = elevationPeaks(points);
  if (static_cast<int>(peaks.size()) == num_beams) {
    assignRingsByElevation(points, peaks, M_PI);
    return KittiRingMethod::kElevationPeaks;
  }
  double low = M_PI, high = -M_PI;
  for (const LidarPoint& pt : points) {
    if (!pt.p.allFinite()) continue;
    const double e = std::atan2(static_cast<double>(pt.p.z()), std::hypot(static_cast<double>(pt.p.x()), static_cast<double>(pt.p.y())));
    low = std::min(low, e);
    high = std::max(high, e);
  }
  if (low > high) low = high = 0.0;
  assignRingsByElevation(points, uniformElevations(num_beams, low, high), M_PI);
  return KittiRingMethod::kUniformFan;
}

}  // namespace

void KittiSequence::setNumBeams(int num_beams) {
  if (num_beams < 1 || num_beams > 255)
    throw std::invalid_argument("KITTI: " + std::to_string(num_beams) + " beams (1..255)");
  num_beams_ = num_beams;
}

LidarScan KittiSequence::scan(std::size_t i, KittiScanReport* report) const {
  if (i >= size())
    throw ReadError("KITTI: scan index " + std::to_string(i) + " out of range (" + std::to_string(size()) + " scans in '" +
                    directory_ + "')");
  LidarScan scan;
  scan.points = readKittiBin(scan_files_[i]);
  scan.utime = utime(i);
  scan.seq = static_cast<std::int64_t>(i);
  scan.sensor = num_beams_ == kKittiNumBeams ? "hdl64" : "";
  scan.num_beams = num_beams_;
  scan.sweep_duration = static_cast<float>(kKittiSweepDuration);
  scan.deskewed = false;

  KittiScanReport local;
  for (LidarPoint& pt : scan.points) {
    if (!pt.p.allFinite()) {
      ++local.nan_points;
      continue;  // dt 0: the preprocessing stage removes it anyway
    }
    pt.dt = kittiPointDt(pt.p.x(), pt.p.y());
  }
  if (!assignRingsByScanOrder(scan.points, num_beams_)) local.ring_method = assignRingsOtherwise(scan.points, num_beams_);
  scan.has_ring = true;
  scan.has_time = true;
  if (report) *report = local;
  return scan;
}

Trajectory KittiSequence::groundTruthLidar(const std::string& poses_file) const {
  const std::vector<Eigen::Isometry3d> camera_poses = readKittiPoses(poses_file);
  const Eigen::Matrix4d Tr = calibration().T_cam0_velo.matrix();
  // General inverse: KITTI's Tr is only orthonormal to ~1e-6; follow the formula exactly.
  const Eigen::Matrix4d Tr_inv = Tr.inverse();
  Trajectory out;
  for (size_t i = 0; i < size(); ++i) {
    const long number = scanNumber(scan_files_[i]);
    const size_t line = number >= 0 ? static_cast<size_t>(number) : i;
    if (line >= camera_poses.size())
      throw ReadError("KITTI: poses file '" + poses_file + "' has no pose for scan '" + scan_files_[i] + "'");
    StampedPose pose;
    pose.utime = utime(i);
    pose.pose.matrix() = Tr_inv * camera_poses[line].matrix() * Tr;
    out.push_back(pose);
  }
  return out;
}

std::string KittiSequence::defaultPosesFile() const {
  const fs::path seq = fs::path(directory_).lexically_normal();
  const fs::path name = seq.filename().empty() ? seq.parent_path().filename() : seq.filename();
  const fs::path sequences = seq.filename().empty() ? seq.parent_path().parent_path() : seq.parent_path();
  return (sequences.parent_path() / "poses" / (name.string() + ".txt")).string();
}

}  // namespace adit::io
