// PNG plots drawn by plot_trajectory.py with Debian's /usr/bin/python3 + matplotlib (Agg, no display).
// The C++ side writes the data to a temporary file and runs the script; it never crashes when
// python or matplotlib is missing: the result says what went wrong.
#pragma once

#include "core/types.hpp"
#include "eval/evaluate.hpp"

#include <string>
#include <vector>

namespace adit::eval {

struct PlotOptions {
  std::string python = "/usr/bin/python3";  // Debian's interpreter: it owns python3-matplotlib
  std::string script;                       // empty: findPlotScript()
  std::string title;                        // figure title (optional)
};

struct PlotResult {
  bool ok = false;
  std::string message;  // on failure: what failed, with the script's stderr
};

// <directory of /proc/self/exe>/../share/adit/plot_trajectory.py (the build copies it there);
// empty if it does not exist.
std::string findPlotScript();

// Top view (x-y) of ground truth vs aligned estimate coloured by APE error with a colour bar, and
// the APE error over time, in one PNG.
PlotResult plotTrajectory(const EvalResult& result, const std::string& png_path, const PlotOptions& options = {});

// Top view of a map point cloud as a density image, optionally with a trajectory drawn over it.
PlotResult plotMapTopView(const std::vector<Eigen::Vector3f>& points, const std::string& png_path,
                          const Trajectory& trajectory = {}, const PlotOptions& options = {});
// Same, reading the cloud from a PCD file (any point type with x, y, z; read by lib/io, which rejects
// corrupt files with a message instead of crashing).
PlotResult plotMapTopViewFromPcd(const std::string& pcd_path, const std::string& png_path,
                                 const Trajectory& trajectory = {}, const PlotOptions& options = {});

}  // namespace adit::eval
