#include "eval/plot.hpp"

#include "io/pcd.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

extern char** environ;

namespace adit::eval {
namespace {

bool fileExists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

// A unique temporary file name (created empty, so no other process can take it).
std::string makeTempFile(const char* suffix_hint) {
  std::string pattern = std::string("/tmp/adit_") + suffix_hint + "_XXXXXX";
  std::vector<char> buf(pattern.begin(), pattern.end());
  buf.push_back('\0');
  const int fd = ::mkstemp(buf.data());
  if (fd < 0) return "";
  ::close(fd);
  return buf.data();
}

// Removes the listed files when it goes out of scope.
struct TempFiles {
  std::vector<std::string> paths;
  ~TempFiles() {
    for (const std::string& p : paths) std::remove(p.c_str());
  }
};

std::string readAll(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs python script args..., stderr captured; returns ok or the reason.
PlotResult runScript(const PlotOptions& options, const std::vector<std::string>& args, TempFiles& temps) {
  PlotResult r;
  const std::string script = options.script.empty() ? findPlotScript() : options.script;
  if (script.empty() || !fileExists(script)) {
    r.message = "plot script plot_trajectory.py not found (expected in <bin>/../share/adit/)";
    return r;
  }
  if (::access(options.python.c_str(), X_OK) != 0) {
    r.message = options.python + " not found: install python3 and python3-matplotlib to get plots";
    return r;
  }
  const std::string err_path = makeTempFile("plot_err");
  temps.paths.push_back(err_path);
  std::vector<std::string> argv_s = {options.python, script};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 2, err_path.c_str(), O_WRONLY | O_TRUNC, 0600);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int spawn_error = posix_spawn(&pid, options.python.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawn_error != 0) {
    r.message = "cannot run " + options.python + ": " + std::strerror(spawn_error);
    return r;
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    r.ok = true;
    return r;
  }
  std::string err = readAll(err_path);
  while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
  r.message = "plot failed (" + options.python + " " + script + ")" + (err.empty() ? "" : ": " + err);
  return r;
}

bool writeTrajectoryXy(const std::string& path, const Trajectory& trajectory) {
  std::ofstream out(path);
  char buf[96];
  for (const StampedPose& p : trajectory) {
    std::snprintf(buf, sizeof buf, "%.6f %.6f\n", p.pose.translation().x(), p.pose.translation().y());
    out << buf;
  }
  return static_cast<bool>(out);
}

}  // namespace

std::string findPlotScript() {
  char buf[4096];
  const ssize_t n = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return "";
  buf[n] = '\0';
  std::string exe(buf);
  const auto slash = exe.rfind('/');
  if (slash == std::string::npos) return "";
  const std::string path = exe.substr(0, slash) + "/../share/adit/plot_trajectory.py";
  return fileExists(path) ? path : "";
}

PlotResult plotTrajectory(const EvalResult& result, const std::string& png_path, const PlotOptions& options) {
  if (!result.valid || result.gt.empty()) return {false, "nothing to plot: " + result.message};
  TempFiles temps;
  const std::string data = makeTempFile("traj");
  if (data.empty()) return {false, "cannot create a temporary file in /tmp"};
  temps.paths.push_back(data);
  {
    std::ofstream out(data);
    out << "# t_s gt_x gt_y gt_z est_x est_y est_z ape_m\n";
    char buf[256];
    const double t0 = toSeconds(result.gt.front().utime);
    for (std::size_t k = 0; k < result.gt.size(); ++k) {
      const Eigen::Vector3d g = result.gt[k].pose.translation(), e = result.est_aligned[k].pose.translation();
      std::snprintf(buf, sizeof buf, "%.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f\n", toSeconds(result.gt[k].utime) - t0,
                    g.x(), g.y(), g.z(), e.x(), e.y(), e.z(), result.ape_errors_m[k]);
      out << buf;
    }
    if (!out) return {false, "cannot write plot data to " + data};
  }
  const std::string title = options.title.empty() ? "APE, alignment " + toString(result.align) : options.title;
  return runScript(options, {"trajectory", data, png_path, title}, temps);
}

PlotResult plotMapTopView(const std::vector<Eigen::Vector3f>& points, const std::string& png_path,
                          const Trajectory& trajectory, const PlotOptions& options) {
  if (points.empty()) return {false, "map has no points"};
  TempFiles temps;
  const std::string cloud = makeTempFile("map");
  const std::string traj = makeTempFile("map_traj");
  if (cloud.empty() || traj.empty()) return {false, "cannot create a temporary file in /tmp"};
  temps.paths = {cloud, traj};
  {
    std::ofstream out(cloud, std::ios::binary);
    for (const Eigen::Vector3f& p : points) {
      if (!p.allFinite()) continue;
      out.write(reinterpret_cast<const char*>(p.data()), 3 * sizeof(float));
    }
    if (!out) return {false, "cannot write map data to " + cloud};
  }
  if (!writeTrajectoryXy(traj, trajectory)) return {false, "cannot write trajectory to " + traj};
  const std::string title = options.title.empty() ? "Map, top view" : options.title;
  return runScript(options, {"map", cloud, png_path, title, traj}, temps);
}

PlotResult plotMapTopViewFromPcd(const std::string& pcd_path, const std::string& png_path,
                                 const Trajectory& trajectory, const PlotOptions& options) {
  if (!fileExists(pcd_path)) return {false, pcd_path + ": no such file"};
  std::vector<Eigen::Vector3f> points;
  try {
    // lib/io validates the header and body size first (PCL itself can crash on a corrupt file).
    const LidarScan cloud = io::readPcdScan(pcd_path, io::PcdFolderConfig{}, 0, 0);
    points.reserve(cloud.points.size());
    for (const LidarPoint& p : cloud.points) points.push_back(p.p);
  } catch (const std::exception& e) {
    return {false, e.what()};
  }
  return plotMapTopView(points, png_path, trajectory, options);
}

}  // namespace adit::eval
