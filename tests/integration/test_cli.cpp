// The `adit` contract end to end with the built programs: import, deterministic replay, a stage process
// driven from a log, and bad input that is counted instead of crashing.
#include "cli_helpers.hpp"

#include <adit/features_t.hpp>
#include <adit/lidar_scan_t.hpp>
#include <adit/point_cloud_t.hpp>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

namespace fs = std::filesystem;
using namespace adit::test;

namespace {

// Imported once for the whole suite: kitti_mini 01 (10 HDL-64E sweeps).
class Cli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = freshDir("cli");
    log_ = dir_ / "kitti01.lcmlog";
    ASSERT_EQ(run(bin("adit") + " import kitti " + kittiSequence("01") + " -o " + log_.string(), dir_ / "import.txt"), 0)
        << slurp(dir_ / "import.txt");
  }
  static fs::path dir_, log_;
};
fs::path Cli::dir_, Cli::log_;

}  // namespace

TEST_F(Cli, ImportWritesEverySweepWithRingsAndTimes) {
  const auto p = payloads(log_.string());
  ASSERT_EQ(p.at("LIDAR_POINTS").size(), 10u);
  // Compact sweeps: KITTI has no firing grid, so the per-point layout.
  adit::lidar_scan_t first;
  const auto& bytes = p.at("LIDAR_POINTS").front();
  ASSERT_GT(first.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  EXPECT_EQ(first.layout, +adit::lidar_scan_t::LAYOUT_POINTS);
  EXPECT_EQ(first.num_beams, 64);
  EXPECT_GT(first.num_points, 100000);
  EXPECT_TRUE(first.flags & adit::point_cloud_t::FLAG_HAS_RING);
  EXPECT_TRUE(first.flags & adit::point_cloud_t::FLAG_HAS_TIME);
}

TEST_F(Cli, ReplayTwiceGivesByteIdenticalOutputs) {
  for (const char* run_name : {"a", "b"})
    ASSERT_EQ(run(bin("adit") + " replay " + log_.string() + " --record-all -o " + (dir_ / run_name).string(),
                  dir_ / "replay.txt"),
              0)
        << slurp(dir_ / "replay.txt");
  const std::string a = slurp(dir_ / "a" / "output.lcmlog"), b = slurp(dir_ / "b" / "output.lcmlog");
  const auto p = payloads((dir_ / "a" / "output.lcmlog").string());
  ASSERT_EQ(p.at("FEATURES").size(), 10u);  // the feature stage ran on every sweep
  EXPECT_EQ(a, b);
  // Every product except timing.json is reproducible.
  for (const auto& entry : fs::directory_iterator(dir_ / "a")) {
    const std::string name = entry.path().filename().string();
    if (name == "timing.json") continue;
    EXPECT_EQ(slurp(entry.path()), slurp(dir_ / "b" / name)) << name << " differs between two replays";
  }
  EXPECT_TRUE(fs::exists(dir_ / "a" / "timing.json"));
}

// The pipelined replay (feature stage and odometry of a sweep beside the mapper and loop closer of the one
// before, runtime/pipelined_bus.hpp) against the one-threaded lockstep bus on a drive where loops close, so
// POSE_GRAPH flows back to the mapper in the middle of the run: every product the same byte for byte.
TEST_F(Cli, PipelinedReplayIsTheOneThreadedReplayByteForByte) {
  const fs::path log = dir_ / "small_loop.lcmlog";
  ASSERT_EQ(run(bin("adit") + " sim --config " ADIT_SOURCE_DIR "/tests/live/small_loop.yaml --duration 105 --seed 1 -o " +
                    log.string(),
                dir_ / "sim_loop.txt"),
            0)
      << slurp(dir_ / "sim_loop.txt");
  for (const char* flags : {"", " --serial"})
    ASSERT_EQ(run(bin("adit") + " replay " + log.string() + " --record-all --no-progress -o " +
                      (dir_ / (*flags ? "loop_serial" : "loop_pipelined")).string() + flags,
                  dir_ / "replay_loop.txt"),
              0)
        << slurp(dir_ / "replay_loop.txt");
  const auto p = payloads((dir_ / "loop_pipelined" / "output.lcmlog").string());
  ASSERT_GT(p.at("ODOM_MAPPED").size(), 1000u);
  const std::string timing = slurp(dir_ / "loop_pipelined" / "timing.json"), key = "\"loops_accepted\": ";
  const std::size_t at = timing.find(key);
  ASSERT_NE(at, std::string::npos);
  EXPECT_GT(std::stoi(timing.substr(at + key.size())), 0)
      << "no loop closed: the feedback from the loop closer to the mapper is not exercised";
  for (const auto& entry : fs::directory_iterator(dir_ / "loop_pipelined")) {
    const std::string name = entry.path().filename().string();
    if (name == "timing.json") continue;
    EXPECT_EQ(slurp(entry.path()), slurp(dir_ / "loop_serial" / name)) << name << " differs from the one-threaded replay";
  }
}

// kitti_mini through import, replay and eval as a user runs them (scripts/accuracy_check.sh's rows). 02 starts
// at 15 m/s (1.5 m between sweeps): before the odometry's start-up search it replayed to APE 2.80 m, the
// estimate stuck at 0.49 m per sweep; a voxel-hash ICP odometry gets 0.025 m on the same sweeps. Measured:
// 02 0.024 m, 01 0.036 m (00's ground truth for these frames is interpolated, ~0.2 m per frame off: left out).
TEST_F(Cli, KittiReplaysTrackFromAMovingStart) {
  for (const std::string seq : {"01", "02"}) {
    const fs::path log = dir_ / ("kitti" + seq + ".lcmlog"), out = dir_ / ("kitti" + seq);
    ASSERT_EQ(run(bin("adit") + " import kitti " + kittiSequence(seq) + " -o " + log.string(), dir_ / "import.txt"), 0);
    ASSERT_EQ(run(bin("adit") + " replay " + log.string() + " --no-progress --config " ADIT_SOURCE_DIR
                      "/launch/sensors/hdl64.yaml -o " + out.string(), dir_ / "replay.txt"), 0)
        << slurp(dir_ / "replay.txt");
    const std::string poses = std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini/poses/" + seq + ".txt";
    ASSERT_EQ(run(bin("adit") + " eval --gt " + poses + " --calib " + kittiSequence(seq) + "/calib.txt --gt-times " +
                      kittiSequence(seq) + "/times.txt --est " + (out / "trajectory.tum").string(),
                  dir_ / "eval.txt"), 0);
    const std::string report = slurp(dir_ / "eval.txt");
    const auto all = report.find("all poses"), rmse = report.find("rmse", all);
    ASSERT_NE(rmse, std::string::npos) << report;
    const double ape = std::stod(report.substr(rmse + 4));
    std::printf("kitti_mini %s replay: APE rmse %.4f m\n", seq.c_str(), ape);
    EXPECT_LE(ape, 0.05) << seq;
  }
}

TEST_F(Cli, StageProcessDrivenFromALogMatchesReplay) {
  // The feature process reads a recording of its inputs through LCM's file:// provider and writes its
  // outputs to another log: the same FEATURES as the same stage inside `adit replay`.
  const fs::path out = dir_ / "feature_process.lcmlog";
  ASSERT_EQ(run(bin("adit-feature") + " --lcm-url 'file://" + log_.string() + "?speed=0' --out-url 'file://" +
                    out.string() + "?mode=w'",
                dir_ / "feature.txt"),
            0)
      << slurp(dir_ / "feature.txt");
  ASSERT_EQ(run(bin("adit") + " replay " + log_.string() + " --stages feature --record-all -o " +
                    (dir_ / "feature_replay").string(),
                dir_ / "replay_feature.txt"),
            0);
  const auto process = payloads(out.string());
  const auto replay = payloads((dir_ / "feature_replay" / "output.lcmlog").string());
  ASSERT_EQ(process.at("FEATURES").size(), 10u);
  EXPECT_EQ(process.at("FEATURES"), replay.at("FEATURES"));
  EXPECT_GE(process.at("STATUS_FEATURE").size(), 2u);  // starting + stopping at least
}

TEST_F(Cli, CorruptAndTruncatedLogsAreSkippedOverNotFatal) {
  std::string bytes = slurp(log_);
  for (std::size_t i = bytes.size() / 3; i < bytes.size() / 3 + 64; ++i) bytes[i] = static_cast<char>(i * 31);
  bytes.resize(bytes.size() - 1000);  // and cut the last sweep short
  const fs::path bad = dir_ / "bad.lcmlog";
  std::ofstream(bad, std::ios::binary | std::ios::trunc) << bytes;
  const fs::path out = dir_ / "bad_replay";
  // Status 3: the outputs cover the readable part of a damaged log.
  ASSERT_EQ(run(bin("adit") + " replay " + bad.string() + " --record-all -o " + out.string(), dir_ / "bad.txt"), 3)
      << slurp(dir_ / "bad.txt");
  const std::string report = slurp(dir_ / "bad.txt");
  EXPECT_NE(report.find("truncated"), std::string::npos) << report;
  const auto p = payloads((out / "output.lcmlog").string());
  // The sweep whose bytes were scrambled fails to decode (counted), the truncated last one is lost, the rest flow.
  EXPECT_GE(p.at("FEATURES").size(), 7u);
  EXPECT_LE(p.at("FEATURES").size(), 9u);
}

TEST_F(Cli, UnreadableKittiScanStopsTheImportUnlessKeepGoing) {
  const fs::path seq = dir_ / "seq_missing";
  fs::create_directories(seq / "velodyne");
  fs::copy_file(kittiSequence("01") + "/times.txt", seq / "times.txt");
  fs::copy_file(kittiSequence("01") + "/calib.txt", seq / "calib.txt");
  for (int i : {0, 1, 3})  // 000002.bin is missing; 000004.bin is empty garbage
    fs::copy_file(kittiSequence("01") + "/velodyne/00000" + std::to_string(i) + ".bin",
                  seq / "velodyne" / ("00000" + std::to_string(i) + ".bin"));
  std::ofstream(seq / "velodyne" / "000004.bin", std::ios::binary) << "garbage";
  const fs::path out = dir_ / "missing.lcmlog";
  ASSERT_EQ(run(bin("adit") + " import kitti " + seq.string() + " -o " + out.string(), dir_ / "strict.txt"), 1)
      << slurp(dir_ / "strict.txt");
  EXPECT_FALSE(fs::exists(out));
  EXPECT_NE(slurp(dir_ / "strict.txt").find("000004.bin"), std::string::npos);
  ASSERT_EQ(run(bin("adit") + " import kitti " + seq.string() + " --keep-going -o " + out.string(), dir_ / "missing.txt"), 0)
      << slurp(dir_ / "missing.txt");
  EXPECT_EQ(payloads(out.string()).at("LIDAR_POINTS").size(), 3u);
  EXPECT_NE(slurp(dir_ / "missing.txt").find("000004.bin"), std::string::npos);
}

TEST_F(Cli, EveryStageProcessRunsThePipelineFromLogs) {
  // Chain the four processes through logs: each reads what the previous one published and publishes its own
  // channel (every sweep, in order) and its STATUS.
  struct Step {
    const char* program;
    const char* output;
    std::size_t expected;
  };
  const std::vector<Step> steps{{"adit-feature", "FEATURES", 10},
                                {"adit-odometry", "ODOM_SCAN", 10},
                                {"adit-mapper", "ODOM_MAPPED", 10},
                                {"adit-loop-closer", "STATUS_LOOP_CLOSER", 2}};  // 9 m: no keyframe revisited
  fs::path input = log_;
  for (const Step& step : steps) {
    const fs::path out = dir_ / (std::string(step.program) + ".lcmlog");
    ASSERT_EQ(run(bin(step.program) + " --lcm-url 'file://" + input.string() + "?speed=0' --out-url 'file://" +
                      out.string() + "?mode=w'",
                  dir_ / (std::string(step.program) + ".txt")),
              0)
        << slurp(dir_ / (std::string(step.program) + ".txt"));
    const auto p = payloads(out.string());
    ASSERT_TRUE(p.count(step.output)) << step.program << " published no " << step.output;
    EXPECT_GE(p.at(step.output).size(), step.expected) << step.program;
    input = out;
  }
}

TEST_F(Cli, SimWritesTheSameLogForTheSameSeed) {
  for (const char* name : {"sim_a", "sim_b"})
    ASSERT_EQ(run(bin("adit") + " sim --world roadway-straight --duration 3 --seed 7 -o " + (dir_ / name).string() +
                      ".lcmlog --gt " + (dir_ / name).string() + ".tum",
                  dir_ / "sim.txt"),
              0)
        << slurp(dir_ / "sim.txt");
  EXPECT_EQ(slurp(dir_ / "sim_a.lcmlog"), slurp(dir_ / "sim_b.lcmlog"));
  const auto p = payloads((dir_ / "sim_a.lcmlog").string());
  EXPECT_EQ(p.at("LIDAR_POINTS").size(), 30u);  // 10 Hz
  EXPECT_EQ(p.at("GROUND_TRUTH").size(), 30u);
  EXPECT_GE(p.at("IMU").size(), 590u);  // 200 Hz
  EXPECT_EQ(slurp(dir_ / "sim_a.tum"), slurp(dir_ / "sim_b.tum"));
}

TEST_F(Cli, AblationRunsTheThreeVariantsAndPrintsOneTable) {
  const fs::path log = dir_ / "ablation.lcmlog", gt = dir_ / "ablation_gt.tum";
  ASSERT_EQ(run(bin("adit") + " sim --world roadway-straight --duration 10 --seed 2 -o " + log.string() + " --gt " +
                    gt.string(),
                dir_ / "ablation_sim.txt"),
            0);
  ASSERT_EQ(run(bin("adit") + " bench ablation " + log.string() + " --gt " + gt.string() + " -o " +
                    (dir_ / "ablation").string(),
                dir_ / "ablation.txt"),
            0)
      << slurp(dir_ / "ablation.txt");
  const std::string out = slurp(dir_ / "ablation.txt");
  for (const char* row : {"A-LOAM ", "+ LinK3D ", "+ LinK3D + Scan Context"})
    EXPECT_NE(out.find(std::string("\n") + row), std::string::npos) << row << " missing in:\n" << out;
  EXPECT_NE(out.find("rmse"), std::string::npos) << out;
  // The variants really differ: plain A-LOAM and the LinK3D-seeded pipeline do not give the same trajectory.
  EXPECT_NE(slurp(dir_ / "ablation" / "A-LOAM" / "trajectory.tum"), slurp(dir_ / "ablation" / "LinK3D" / "trajectory.tum"));

  // Ground truth known only up to scale (here: 1.5 times too large): --align sim3 finds the scale and says so.
  std::istringstream lines(slurp(gt));
  std::ofstream scaled(dir_ / "ablation_gt_scaled.tum");
  for (std::string line; std::getline(lines, line);) {
    std::istringstream f(line);
    double t, x, y, z, qx, qy, qz, qw;
    if (!(f >> t >> x >> y >> z >> qx >> qy >> qz >> qw)) continue;
    scaled << fmt::format("{:.6f} {:.6f} {:.6f} {:.6f} {} {} {} {}\n", t, 1.5 * x, 1.5 * y, 1.5 * z, qx, qy, qz, qw);
  }
  scaled.close();
  ASSERT_EQ(run(bin("adit") + " bench ablation " + log.string() + " --gt " + (dir_ / "ablation_gt_scaled.tum").string() +
                    " --align sim3 -o " + (dir_ / "ablation_sim3").string(),
                dir_ / "ablation_sim3.txt"),
            0)
      << slurp(dir_ / "ablation_sim3.txt");
  const std::string sim3 = slurp(dir_ / "ablation_sim3.txt");
  EXPECT_NE(sim3.find("sim3-aligned"), std::string::npos) << sim3;
  int scales = 0;
  for (std::size_t at = sim3.find(", scale "); at != std::string::npos; at = sim3.find(", scale ", at + 1), ++scales)
    EXPECT_NEAR(std::stod(sim3.substr(at + 8)), 1.5, 0.01) << sim3;
  EXPECT_EQ(scales, 3) << sim3;
}

TEST_F(Cli, DemoEndsWithAReportAndPlots) {
  const fs::path out = dir_ / "demo";
  ASSERT_EQ(run(bin("adit") + " demo --duration 12 -o " + out.string(), dir_ / "demo.txt"), 0) << slurp(dir_ / "demo.txt");
  const std::string report = slurp(dir_ / "demo.txt");
  for (const char* line : {"distance travelled", "loops closed", "APE rmse", "real time", "map.pcd", "trajectory.png"})
    EXPECT_NE(report.find(line), std::string::npos) << line << " missing in:\n" << report;
  for (const char* file : {"map.pcd", "trajectory.tum", "odometry.tum", "ground_truth.tum", "trajectory.png", "map.png"})
    EXPECT_TRUE(fs::exists(out / file)) << file;
  // The saved map against the simulator's surfaces (measured: 0.038 m mean over 12 s, 0.01 % of the points
  // beyond 0.2 m, with the mapper's edge lines through the nearest map point; 0.028 m and 0.00 % without).
  const std::size_t at = report.find("map against world");
  ASSERT_NE(at, std::string::npos) << report;
  EXPECT_LT(std::stod(report.substr(at + 17)), 0.06) << report;
  const std::size_t share = report.find(" % of ", at);
  ASSERT_NE(share, std::string::npos) << report;
  const std::size_t start = report.rfind(' ', share - 1);
  EXPECT_LT(std::stod(report.substr(start + 1, share - start - 1)), 0.05) << report;
}

// --extend joins the run to a saved map: without the map (--prior-map) or a place for the result (--save-bundle)
// it is refused before anything runs, naming what is missing.
TEST_F(Cli, ExtendWithoutAPriorMapOrABundleToSaveIsRefused) {
  for (const std::string& missing : {std::string(" --save-bundle ") + (dir_ / "joined").string(), std::string(" --prior-map ") + dir_.string()}) {
    const fs::path out = dir_ / "extend_refused";
    EXPECT_NE(run(bin("adit") + " replay " + log_.string() + " --extend" + missing + " -o " + out.string(), dir_ / "extend.txt"), 0);
    const std::string report = slurp(dir_ / "extend.txt");
    EXPECT_NE(report.find("needs --prior-map"), std::string::npos) << report;
    EXPECT_FALSE(fs::exists(out / "output.lcmlog"));
    EXPECT_FALSE(fs::exists(dir_ / "joined"));
  }
}

// A run saved as a map bundle is summarised by `adit info`, which also writes its keyframes' poses as TUM.
TEST_F(Cli, InfoSummarisesABundleAndWritesItsKeyframes) {
  const fs::path bundle = dir_ / "bundle", out = dir_ / "bundle_run", tum = dir_ / "keyframes.tum";
  ASSERT_EQ(run(bin("adit") + " replay " + log_.string() + " --no-progress --config " ADIT_SOURCE_DIR
                    "/launch/sensors/hdl64.yaml --save-bundle " + bundle.string() + " -o " + out.string(), dir_ / "bundle.txt"), 0)
      << slurp(dir_ / "bundle.txt");
  ASSERT_EQ(run(bin("adit") + " info " + bundle.string() + " --keyframes " + tum.string(), dir_ / "info.txt"), 0)
      << slurp(dir_ / "info.txt");
  const std::string info = slurp(dir_ / "info.txt");
  const auto at = info.find("\n  keyframes");
  ASSERT_NE(at, std::string::npos) << info;
  const int keyframes = std::stoi(info.substr(info.find_first_of("0123456789", at)));
  EXPECT_GT(keyframes, 0);
  std::istringstream lines(slurp(tum));
  int poses = 0;
  for (std::string line; std::getline(lines, line);) poses += !line.empty() && line[0] != '#';
  EXPECT_EQ(poses, keyframes);
}
