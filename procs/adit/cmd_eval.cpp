// `adit eval`: evaluate an estimated trajectory against ground truth (APE, RPE, drift, end point),
// print the report, optionally write JSON and a PNG plot. All the work is in lib/eval.
#include <CLI/CLI.hpp>

#include "eval/evaluate.hpp"
#include "eval/plot.hpp"
#include "eval/report.hpp"
#include "eval/trajectory_io.hpp"

#include <iostream>
#include <memory>
#include <string>

namespace {

struct EvalOptions {
  std::string gt, est, align = "se3", format = "auto", calib, gt_times, est_times, plot, json, save_aligned;
  double max_time_diff_s = 0.01;
};

// KITTI files are camera-frame poses: with --calib they are moved to the lidar frame.
adit::Trajectory load(const std::string& path, const std::string& format, const std::string& times_path,
                      const std::string& calib) {
  using adit::eval::TrajectoryFormat;
  const TrajectoryFormat f = format == "auto" ? adit::eval::detectFormat(path) : adit::eval::parseFormat(format);
  if (f == TrajectoryFormat::kTum) return adit::eval::readTum(path);
  const std::vector<double> times = times_path.empty() ? std::vector<double>{} : adit::eval::readTimes(times_path);
  adit::Trajectory t = adit::eval::readKitti(path, times);
  if (!calib.empty()) t = adit::eval::cameraToLidar(t, adit::eval::readKittiVeloToCam(calib));
  return t;
}

int runEval(const EvalOptions& o) {
  adit::eval::EvalConfig config;
  config.align = adit::eval::parseAlignMode(o.align);
  config.max_time_diff_s = o.max_time_diff_s;
  const adit::Trajectory gt = load(o.gt, o.format, o.gt_times, o.calib);
  const adit::Trajectory est = load(o.est, o.format, o.est_times, o.calib);
  const adit::eval::EvalResult result = adit::eval::evaluate(gt, est, config);
  std::cout << "ground truth: " << o.gt << "\nestimate:     " << o.est << "\n" << adit::eval::formatReport(result);
  if (!o.json.empty()) {
    adit::eval::writeTextFile(o.json, adit::eval::toJson(result));
    std::cout << "JSON written to " << o.json << "\n";
  }
  if (!result.valid) return 1;
  if (!o.save_aligned.empty()) {
    adit::eval::writeTum(o.save_aligned, result.est_aligned);
    std::cout << "aligned estimate written to " << o.save_aligned << "\n";
  }
  if (!o.plot.empty()) {
    const adit::eval::PlotResult plot = adit::eval::plotTrajectory(result, o.plot);
    if (!plot.ok) {
      std::cerr << "adit eval: no plot: " << plot.message << "\n";
      return 1;
    }
    std::cout << "plot written to " << o.plot << "\n";
  }
  return 0;
}

}  // namespace

void registerEvalCommand(CLI::App& app) {
  auto o = std::make_shared<EvalOptions>();
  CLI::App* sub = app.add_subcommand(
      "eval", "Evaluate a trajectory against ground truth: APE, RPE per 1/10/100 m, KITTI drift, end-point error");
  sub->add_option("--gt", o->gt, "ground-truth trajectory file (TUM or KITTI)")->required()->check(CLI::ExistingFile);
  sub->add_option("--est", o->est, "estimated trajectory file (TUM or KITTI)")->required()->check(CLI::ExistingFile);
  sub->add_option("--align", o->align, "alignment of the estimate onto the ground truth (Umeyama)")
      ->capture_default_str()
      ->check(CLI::IsMember({"se3", "sim3", "none"}));
  sub->add_option("--format", o->format,
                  "file format of both files: tum (t x y z qx qy qz qw), kitti (3x4 row-major) or auto "
                  "(detected per file)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "tum", "kitti"}));
  sub->add_option("--calib", o->calib,
                  "KITTI calib.txt: KITTI-format (camera-frame) poses are converted to the lidar frame")
      ->check(CLI::ExistingFile);
  sub->add_option("--gt-times", o->gt_times, "times.txt for a KITTI ground truth (default: pose index x 0.1 s)")
      ->check(CLI::ExistingFile);
  sub->add_option("--est-times", o->est_times, "times.txt for a KITTI estimate (default: pose index x 0.1 s)")
      ->check(CLI::ExistingFile);
  sub->add_option("--max-time-diff", o->max_time_diff_s, "largest timestamp difference of a matched pair, s")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--plot", o->plot, "write a PNG: top view coloured by APE and APE over time");
  sub->add_option("--json", o->json, "write all numbers as JSON");
  sub->add_option("--save-aligned", o->save_aligned, "write the matched, aligned estimate as TUM");
  sub->callback([o]() {
    int code = 0;
    try {
      code = runEval(*o);
    } catch (const std::exception& e) {
      std::cerr << "error adit eval: " << e.what() << "\n";
      code = 1;
    }
    if (code != 0) throw CLI::RuntimeError(code);
  });
}
