// `adit eval` end to end through CLI11 (the same registerEvalCommand the adit binary uses).
#include <CLI/CLI.hpp>

#include "eval/trajectory_io.hpp"
#include "fixtures.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>

void registerEvalCommand(CLI::App& app);

namespace adit::eval {
namespace {

const std::string kKitti = std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini";

// Runs `adit eval <args>`; returns stdout. Exceptions (help, errors) propagate.
std::string runEval(std::vector<std::string> args) {
  CLI::App app("adit");
  registerEvalCommand(app);
  args.insert(args.begin(), {"adit", "eval"});
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  std::ostringstream captured;
  std::streambuf* old = std::cout.rdbuf(captured.rdbuf());
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (...) {
    std::cout.rdbuf(old);
    throw;
  }
  std::cout.rdbuf(old);
  return captured.str();
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The number after "<key>": following the first occurrence of `section` in a JSON text.
double jsonNumber(const std::string& json, const std::string& section, const std::string& key) {
  const auto s = json.find("\"" + section + "\"");
  if (s == std::string::npos) return NAN;
  const auto k = json.find("\"" + key + "\": ", s);
  if (k == std::string::npos) return NAN;
  return std::strtod(json.c_str() + k + key.size() + 4, nullptr);
}

TEST(CmdEval, HelpListsTheOptions) {
  CLI::App app("adit");
  registerEvalCommand(app);
  const std::string help = app.get_subcommand("eval")->help();
  for (const char* opt : {"--gt", "--est", "--align", "--format", "--calib", "--plot", "--json"})
    EXPECT_NE(help.find(opt), std::string::npos) << opt;
  EXPECT_THROW(runEval({"--help"}), CLI::CallForHelp);
}

TEST(CmdEval, TumFilesReportJsonAndPlot) {
  const Trajectory gt = test::windingPath(300);
  const Trajectory est = test::transformed(gt, Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0.6, 0.8));
  const std::string gt_path = test::tempPath("cli_gt.tum"), est_path = test::tempPath("cli_est.tum");
  const std::string json = test::tempPath("cli.json"), png = test::tempPath("cli.png");
  writeTum(gt_path, gt);
  writeTum(est_path, est);

  const std::string out = runEval({"--gt", gt_path, "--est", est_path, "--align", "none", "--json", json, "--plot", png});
  EXPECT_NE(out.find("rmse 1.0000"), std::string::npos) << out;
  EXPECT_NE(out.find("End-point error: 1.0000 m"), std::string::npos) << out;
  const std::string j = readFile(json);
  EXPECT_NEAR(jsonNumber(j, "ape_translation_m", "rmse"), 1.0, 1e-8);
  EXPECT_NEAR(jsonNumber(j, "end_point", "error_m"), 1.0, 1e-8);
  EXPECT_GT(readFile(png).size(), 20000u);

  // Default se3 alignment removes the offset.
  runEval({"--gt", gt_path, "--est", est_path, "--json", json});
  EXPECT_LT(jsonNumber(readFile(json), "ape_translation_m", "rmse"), 1e-6);
  for (const std::string& p : {gt_path, est_path, json, png}) std::remove(p.c_str());
}

TEST(CmdEval, KittiGroundTruthWithCalibAgainstLidarFrameTum) {
  // The lidar-frame ground truth written as TUM must evaluate to ~0 against the KITTI camera-frame file + calib.
  const Trajectory cam = readKitti(kKitti + "/poses/01.txt", readTimes(kKitti + "/sequences/01/times.txt"));
  const Trajectory velo = cameraToLidar(cam, readKittiVeloToCam(kKitti + "/sequences/01/calib.txt"));
  const std::string est_path = test::tempPath("cli_velo.tum"), json = test::tempPath("cli_kitti.json");
  writeTum(est_path, velo);
  runEval({"--gt", kKitti + "/poses/01.txt", "--gt-times", kKitti + "/sequences/01/times.txt", "--calib",
           kKitti + "/sequences/01/calib.txt", "--est", est_path, "--align", "none", "--json", json});
  const std::string j = readFile(json);
  EXPECT_NEAR(jsonNumber(j, "poses", "matched"), 10.0, 0.0);
  EXPECT_LT(jsonNumber(j, "ape_translation_m", "max"), 1e-6);
  EXPECT_NEAR(jsonNumber(j, "distance_m", "ground_truth"), 9.3, 1.0);  // ~1 m per scan on the highway

  // Without the calib the frames differ (camera z forward vs lidar x forward): a large error unaligned.
  runEval({"--gt", kKitti + "/poses/01.txt", "--gt-times", kKitti + "/sequences/01/times.txt", "--est", est_path,
           "--align", "none", "--json", json});
  EXPECT_GT(jsonNumber(readFile(json), "ape_translation_m", "max"), 5.0);
  std::remove(est_path.c_str());
  std::remove(json.c_str());
}

TEST(CmdEval, BadInputsFailCleanly) {
  const std::string bad = test::tempPath("cli_bad.tum"), good = test::tempPath("cli_good.tum");
  std::ofstream(bad) << "0 0 0 0 0 0 0 1\n0.1 0 0 zero 0 0 0 1\n";
  writeTum(good, test::windingPath(20));
  try {
    runEval({"--gt", good, "--est", bad});
    ADD_FAILURE() << "malformed estimate accepted";
  } catch (const CLI::RuntimeError& e) {
    EXPECT_EQ(e.get_exit_code(), 1);
  }
  EXPECT_THROW(runEval({"--gt", good, "--est", "/nonexistent.tum"}), CLI::ValidationError);
  EXPECT_THROW(runEval({"--gt", good, "--est", good, "--align", "affine"}), CLI::ValidationError);
  // No common timestamps: report says so, exit code 1.
  writeTum(bad, test::windingPath(20, 5000.0));
  EXPECT_THROW(runEval({"--gt", good, "--est", bad}), CLI::RuntimeError);
  std::remove(bad.c_str());
  std::remove(good.c_str());
}

}  // namespace
}  // namespace adit::eval
