#include "eval/trajectory_io.hpp"

#include "io/atomic_file.hpp"

#include <Eigen/SVD>

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace adit::eval {
namespace {

[[noreturn]] void fail(const std::string& path, int line, const std::string& what) {
  throw std::runtime_error(path + ":" + std::to_string(line) + ": " + what);
}

std::ifstream openOrThrow(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
    throw std::runtime_error(path + ": not a regular file");
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open file");
  return in;
}

// Splits a data line into numbers (whitespace or commas separate them). Returns false for a
// comment or blank line. Throws naming the line on a token that is not a finite number.
bool parseNumbers(const std::string& text, const std::string& path, int line, std::vector<double>& out) {
  out.clear();
  std::string cleaned = text;
  for (char& c : cleaned)
    if (c == ',' || c == '\r') c = ' ';
  std::istringstream tokens(cleaned);
  std::string token;
  while (tokens >> token) {
    if (out.empty() && token[0] == '#') return false;
    char* end = nullptr;
    const double value = std::strtod(token.c_str(), &end);
    if (end == token.c_str() || *end != '\0') fail(path, line, "'" + token + "' is not a number");
    if (!std::isfinite(value)) fail(path, line, "'" + token + "' is not a finite number");
    out.push_back(value);
  }
  return !out.empty();
}

// Nearest rotation (SVD projection): KITTI prints 7 significant digits, so its 3x3 blocks are
// orthonormal only to ~1e-7; downstream quaternion and angle code expects an exact rotation.
bool toRotation(const Eigen::Matrix3d& M, Eigen::Matrix3d& R) {
  if ((M.transpose() * M - Eigen::Matrix3d::Identity()).norm() > 1e-2 || M.determinant() <= 0.0) return false;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  R = svd.matrixU() * svd.matrixV().transpose();
  return true;
}

Eigen::Isometry3d poseFrom3x4(const std::vector<double>& v, std::size_t first, const std::string& path, int line) {
  Eigen::Matrix3d M;
  Eigen::Vector3d t;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) M(r, c) = v[first + static_cast<std::size_t>(4 * r + c)];
    t[r] = v[first + static_cast<std::size_t>(4 * r + 3)];
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d R;
  if (!toRotation(M, R)) fail(path, line, "the 3x3 block is not a rotation matrix");
  T.linear() = R;
  T.translation() = t;
  return T;
}

std::string formatSeconds(std::int64_t utime) {
  const bool negative = utime < 0;
  const std::uint64_t magnitude = negative ? static_cast<std::uint64_t>(-(utime + 1)) + 1u : static_cast<std::uint64_t>(utime);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s%" PRIu64 ".%06" PRIu64, negative ? "-" : "", magnitude / 1000000u,
                magnitude % 1000000u);
  return buf;
}

}  // namespace

Trajectory readTum(const std::string& path) {
  std::ifstream in = openOrThrow(path);
  Trajectory out;
  std::string text;
  std::vector<double> v;
  for (int line = 1; std::getline(in, text); ++line) {
    if (!parseNumbers(text, path, line, v)) continue;
    if (v.size() != 8) fail(path, line, "expected 8 numbers 't x y z qx qy qz qw', found " + std::to_string(v.size()));
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (q.norm() < 1e-6) fail(path, line, "quaternion has zero norm");
    StampedPose p;
    p.utime = toUtime(v[0]);
    p.pose.linear() = q.normalized().toRotationMatrix();
    p.pose.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    out.push_back(p);
  }
  return out;
}

void writeTum(const std::string& path, const Trajectory& trajectory) {
  std::string content = "# timestamp x y z qx qy qz qw\n";
  char buf[256];
  for (const StampedPose& p : trajectory) {
    Eigen::Quaterniond q(p.pose.linear());
    q.normalize();
    if (q.w() < 0) q.coeffs() = -q.coeffs();  // one sign, so equal poses print equal text
    const Eigen::Vector3d& t = p.pose.translation();
    std::snprintf(buf, sizeof buf, " %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", t.x(), t.y(), t.z(), q.x(), q.y(), q.z(),
                  q.w());
    content += formatSeconds(p.utime) + buf;
  }
  io::writeFileAtomically(path, content);
}

Trajectory readKitti(const std::string& path, const std::vector<double>& times, double frame_period_s) {
  std::ifstream in = openOrThrow(path);
  Trajectory out;
  std::string text;
  std::vector<double> v;
  for (int line = 1; std::getline(in, text); ++line) {
    if (!parseNumbers(text, path, line, v)) continue;
    if (v.size() != 12) fail(path, line, "expected 12 numbers (3x4 row-major pose), found " + std::to_string(v.size()));
    const std::size_t index = out.size();
    if (!times.empty() && index >= times.size())
      fail(path, line, "more poses than timestamps (" + std::to_string(times.size()) + ")");
    StampedPose p;
    p.utime = toUtime(times.empty() ? static_cast<double>(index) * frame_period_s : times[index]);
    p.pose = poseFrom3x4(v, 0, path, line);
    out.push_back(p);
  }
  return out;
}

void writeKitti(const std::string& path, const Trajectory& trajectory) {
  std::string content;
  char buf[64];
  for (const StampedPose& p : trajectory) {
    const Eigen::Matrix4d M = p.pose.matrix();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) {
        std::snprintf(buf, sizeof buf, "%s%.12e", (r == 0 && c == 0) ? "" : " ", M(r, c));
        content += buf;
      }
    content += '\n';
  }
  io::writeFileAtomically(path, content);
}

std::vector<double> readTimes(const std::string& path) {
  std::ifstream in = openOrThrow(path);
  std::vector<double> out;
  std::string text;
  std::vector<double> v;
  for (int line = 1; std::getline(in, text); ++line) {
    if (!parseNumbers(text, path, line, v)) continue;
    if (v.size() != 1) fail(path, line, "expected one timestamp, found " + std::to_string(v.size()) + " numbers");
    out.push_back(v[0]);
  }
  return out;
}

Eigen::Isometry3d readKittiVeloToCam(const std::string& calib_path) {
  std::ifstream in = openOrThrow(calib_path);
  std::string text;
  std::vector<double> v;
  for (int line = 1; std::getline(in, text); ++line) {
    const auto colon = text.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = text.substr(0, colon);
    if (key != "Tr" && key != "Tr_velo_to_cam") continue;
    if (!parseNumbers(text.substr(colon + 1), calib_path, line, v) || v.size() != 12)
      fail(calib_path, line, key + " needs 12 numbers (3x4 row-major)");
    return poseFrom3x4(v, 0, calib_path, line);
  }
  throw std::runtime_error(calib_path + ": no 'Tr:' line (velodyne to camera transform)");
}

Trajectory cameraToLidar(const Trajectory& camera_poses, const Eigen::Isometry3d& velo_to_cam) {
  Trajectory out = camera_poses;
  const Eigen::Isometry3d cam_to_velo = velo_to_cam.inverse();
  for (StampedPose& p : out) p.pose = cam_to_velo * p.pose * velo_to_cam;
  return out;
}

Trajectory lidarToCamera(const Trajectory& lidar_poses, const Eigen::Isometry3d& velo_to_cam) {
  Trajectory out = lidar_poses;
  const Eigen::Isometry3d cam_to_velo = velo_to_cam.inverse();
  for (StampedPose& p : out) p.pose = velo_to_cam * p.pose * cam_to_velo;
  return out;
}

void writeTextFile(const std::string& path, const std::string& content) { io::writeFileAtomically(path, content); }

TrajectoryFormat detectFormat(const std::string& path) {
  std::ifstream in = openOrThrow(path);
  std::string text;
  std::vector<double> v;
  for (int line = 1; std::getline(in, text); ++line) {
    if (!parseNumbers(text, path, line, v)) continue;
    if (v.size() == 8) return TrajectoryFormat::kTum;
    if (v.size() == 12) return TrajectoryFormat::kKitti;
    fail(path, line, "neither TUM (8 numbers) nor KITTI (12 numbers): " + std::to_string(v.size()) + " numbers");
  }
  throw std::runtime_error(path + ": no poses in file");
}

TrajectoryFormat parseFormat(const std::string& name) {
  if (name == "tum") return TrajectoryFormat::kTum;
  if (name == "kitti") return TrajectoryFormat::kKitti;
  throw std::invalid_argument("unknown trajectory format '" + name + "' (use tum or kitti)");
}

}  // namespace adit::eval
