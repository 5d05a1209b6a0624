// Bad files never hang or crash a command. For each reader: the inputs a user or a broken disk can produce
// (empty, cut short, random bytes, another format's file, and the reader's own traps), each through the
// real command. Pass = exits within kTimeLimitS, non-zero status, an error line naming the file, no crash
// message, and no output left under its final name (nor a temp file).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
constexpr double kTimeLimitS = 20.0;

std::string bin(const std::string& program) { return std::string(ADIT_BIN_DIR) + "/" + program; }
const std::string kKitti = std::string(ADIT_SHARED_DATA_DIR) + "/kitti_mini/sequences/00";

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), {}};
}
void spit(const fs::path& p, const std::string& bytes) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}
std::string randomBytes(std::size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::string s(n, '\0');
  for (char& c : s) c = static_cast<char>(rng() & 0xFF);
  return s;
}

struct Outcome {
  int status = -1;
  double seconds = 0;
  std::string output;
};

Outcome run(const std::string& command, const fs::path& dir) {
  const fs::path log = dir / "command.log";
  const auto start = std::chrono::steady_clock::now();
  const std::string line = "timeout -s KILL " + std::to_string(static_cast<int>(kTimeLimitS) + 10) + " " + command +
                           " > '" + log.string() + "' 2>&1 < /dev/null";
  const int status = std::system(line.c_str());
  Outcome o;
  o.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  o.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  o.output = slurp(log);
  return o;
}

// One malformed input: `make` writes it into a fresh folder and returns the command and the file the
// error must name; `outputs` are the paths (relative to the folder) that must not exist afterwards.
struct Case {
  std::string reader, what;
  std::function<std::string(const fs::path&)> make;
  std::vector<std::string> outputs;
};

struct Tally {
  int tried = 0, survived = 0;
};

class BadFiles : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("adit_badfiles_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    // A small valid log (2 KITTI sweeps) to cut and to take bytes from.
    const fs::path seq = root_ / "good_seq";
    fs::create_directories(seq / "velodyne");
    spit(seq / "times.txt", "0.0\n0.103\n");
    for (const char* s : {"000000.bin", "000001.bin"}) fs::copy_file(kKitti + "/velodyne/" + s, seq / "velodyne" / s);
    const Outcome o = run(bin("adit") + " import kitti " + seq.string() + " -o " + (root_ / "good.lcmlog").string(), root_);
    ASSERT_EQ(o.status, 0) << o.output;
    good_log_ = slurp(root_ / "good.lcmlog");
    good_bin_ = slurp(kKitti + "/velodyne/000000.bin");
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }

  void check(const Case& c) {
    const fs::path dir = root_ / ("case" + std::to_string(next_++));
    fs::create_directories(dir);
    const std::string command_and_file = c.make(dir);
    const auto bar = command_and_file.find('|');
    const std::string command = command_and_file.substr(0, bar), named = command_and_file.substr(bar + 1);
    const Outcome o = run(command, dir);
    SCOPED_TRACE(c.reader + " / " + c.what + ": " + command + "\n" + o.output);
    bool ok = true;
    const auto expect = [&](bool condition, const std::string& why) {
      EXPECT_TRUE(condition) << why;
      ok = ok && condition;
    };
    expect(o.seconds < kTimeLimitS, "took " + std::to_string(o.seconds) + " s");
    expect(o.status != 0 && o.status < 128, "exit status " + std::to_string(o.status));
    std::istringstream lines(o.output);
    std::string line;
    int error_lines = 0;
    bool names_file = false;
    while (std::getline(lines, line)) {
      if (line.find("error") == std::string::npos && line.find("ERROR") == std::string::npos) continue;
      ++error_lines;
      names_file = names_file || line.find(named) != std::string::npos;
    }
    expect(names_file, "no error line names '" + named + "'");
    expect(error_lines <= 2, std::to_string(error_lines) + " error lines");
    for (const char* crash : {"terminate called", "Segmentation", "Aborted", "AddressSanitizer", "runtime error:"})
      expect(o.output.find(crash) == std::string::npos, std::string("crash message: ") + crash);
    for (const auto& out : c.outputs) expect(!fs::exists(dir / out), "left " + out);
    for (const auto& e : fs::recursive_directory_iterator(dir))
      expect(e.path().filename().string().find(".tmp.") == std::string::npos, "left temp file " + e.path().string());
    Tally& t = tally_[c.reader];
    ++t.tried;
    t.survived += ok ? 1 : 0;
  }

  static void printTable() {
    std::printf("malformed files per reader: tried / survived\n");
    for (const auto& [reader, t] : tally_) std::printf("  %-22s %2d / %2d\n", reader.c_str(), t.tried, t.survived);
  }

  static inline fs::path root_;
  static inline std::string good_log_, good_bin_;
  static inline std::map<std::string, Tally> tally_;
  static inline int next_ = 0;
};

// The generic four: empty, cut short, random, another format's bytes; `wrong` is that other format.
std::vector<std::pair<std::string, std::string>> generic(const std::string& good, const std::string& wrong, unsigned seed) {
  return {{"empty", ""},
          {"truncated", good.substr(0, good.size() / 2 + 5)},  // mid-line, mid-point, mid-frame
          {"random bytes", randomBytes(4096 + seed % 100, seed)},
          {"wrong type", wrong}};
}

const std::string kPcd =
    "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n"
    "1 2 3\n4 5 6\n7 8 9\n";
const std::string kYaml = "name: sim\nprocesses:\n  - name: a\n    command: [adit-feature, --config, \"x.yaml\"]\n";

TEST_F(BadFiles, EveryReaderFailsCleanly) {
  std::vector<Case> cases;
  // adit import pcd: the folder's one file is bad.
  auto pcd_inputs = generic(kPcd, good_bin_.substr(0, 16 * 50 + 4), 1);
  pcd_inputs.push_back({"ascii garbage", kPcd.substr(0, kPcd.size() - 6) + "7 x 9\n"});
  pcd_inputs.push_back({"huge WIDTH", "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 4000000000\nHEIGHT 4000000000\nDATA binary\n"});
  pcd_inputs.push_back({"short binary", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 100\nDATA binary\n" + std::string(50, 'x')});
  for (const auto& [what, bytes] : pcd_inputs)
    cases.push_back({"PCD (import pcd)", what, [bytes = bytes](const fs::path& d) {
                       spit(d / "in" / "000001.pcd", bytes);
                       return bin("adit") + " import pcd " + (d / "in").string() + " -o " + (d / "out.lcmlog").string() +
                              "|000001.pcd";
                     }, {"out.lcmlog"}});
  // adit import kitti: a bad scan, then a bad times.txt.
  auto bin_inputs = generic(good_bin_, kPcd, 2);
  bin_inputs.push_back({"odd size", good_bin_.substr(0, 16 * 1000 + 7)});
  bin_inputs.push_back({"huge (300 MB, sparse)", std::string("\0huge", 5)});  // marker: resized below
  for (const auto& [what, bytes] : bin_inputs)
    cases.push_back({"KITTI .bin (import kitti)", what, [bytes = bytes](const fs::path& d) {
                       spit(d / "seq" / "times.txt", "0.0\n");
                       spit(d / "seq" / "velodyne" / "000000.bin", bytes);
                       if (bytes == std::string("\0huge", 5)) fs::resize_file(d / "seq" / "velodyne" / "000000.bin", 300u << 20);
                       return bin("adit") + " import kitti " + (d / "seq").string() + " -o " + (d / "out.lcmlog").string() +
                              "|000000.bin";
                     }, {"out.lcmlog"}});
  auto times_inputs = generic("0.0\n0.103\n0.207\n", good_bin_.substr(0, 2000), 3);
  times_inputs[1].second = "0.0\n";  // truncated: one line short of the two scans
  times_inputs.push_back({"not numbers", "0.0\nzero point one\n"});
  for (const auto& [what, bytes] : times_inputs)
    cases.push_back({"KITTI times.txt (import kitti)", what, [bytes = bytes](const fs::path& d) {
                       spit(d / "seq" / "times.txt", bytes);
                       spit(d / "seq" / "velodyne" / "000000.bin", std::string(32, '\0'));
                       spit(d / "seq" / "velodyne" / "000001.bin", std::string(32, '\0'));
                       return bin("adit") + " import kitti " + (d / "seq").string() + " -o " + (d / "out.lcmlog").string() +
                              "|times.txt";
                     }, {"out.lcmlog"}});
  // adit info and adit replay on a bad log. A truncated log is used as far as it reads, with exit status 3.
  auto log_inputs = generic(good_log_, kPcd, 4);
  std::string corrupt = good_log_;
  corrupt[28 + 4] = static_cast<char>(0x7F);  // a byte of the first frame's channel name turns unprintable
  log_inputs.push_back({"corrupt first frame", corrupt});
  const unsigned char liar[28] = {0xED, 0xA1, 0xDA, 0x01, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1,
                                  0, 0, 0, 3, 0x1F, 0xFF, 0xFF, 0xFF};
  log_inputs.push_back({"frame announcing 512 MB", std::string(reinterpret_cast<const char*>(liar), 28) + "IMU" + std::string(100, 'x')});
  for (const auto& [what, bytes] : log_inputs) {
    cases.push_back({"LCM log (info)", what, [bytes = bytes](const fs::path& d) {
                       spit(d / "in.lcmlog", bytes);
                       return bin("adit") + " info " + (d / "in.lcmlog").string() + "|in.lcmlog";
                     }, {}});
    const bool damaged_but_readable = what == "truncated" || what == "corrupt first frame";
    cases.push_back({"LCM log (replay)", what, [bytes = bytes](const fs::path& d) {
                       spit(d / "in.lcmlog", bytes);
                       return bin("adit") + " replay " + (d / "in.lcmlog").string() + " -o " + (d / "out").string() +
                              " --stages feature --no-progress|in.lcmlog";
                     }, damaged_but_readable ? std::vector<std::string>{} : std::vector<std::string>{"out/output.lcmlog"}});
    cases.push_back({"LCM log (export mcap)", what, [bytes = bytes](const fs::path& d) {
                       spit(d / "in.lcmlog", bytes);
                       return bin("adit") + " export mcap " + (d / "in.lcmlog").string() + " -o " +
                              (d / "out.mcap").string() + "|in.lcmlog";
                     }, damaged_but_readable ? std::vector<std::string>{} : std::vector<std::string>{"out.mcap"}});
  }
  // adit eval on a bad estimate.
  const std::string tum = "0.0 0 0 0 0 0 0 1\n0.1 1 0 0 0 0 0 1\n0.2 2 0 0 0 0 0 1\n";
  auto tum_inputs = generic(tum, good_bin_.substr(0, 3000), 5);
  tum_inputs.push_back({"NaN position", "0.0 0 0 0 0 0 0 1\n0.1 nan 0 0 0 0 0 1\n"});
  tum_inputs.push_back({"zero quaternion", "0.0 0 0 0 0 0 0 1\n0.1 1 0 0 0 0 0 0\n"});
  for (const auto& [what, bytes] : tum_inputs)
    cases.push_back({"trajectory (eval)", what, [bytes = bytes, tum](const fs::path& d) {
                       spit(d / "gt.tum", tum);
                       spit(d / "est.tum", bytes);
                       return bin("adit") + " eval --gt " + (d / "gt.tum").string() + " --est " + (d / "est.tum").string() +
                              " --json " + (d / "eval.json").string() + "|est.tum";
                     }, {"eval.json"}});
  // adit config --config and adit launch on bad YAML.
  const std::string pipeline = slurp(std::string(ADIT_SOURCE_DIR) + "/launch/config/pipeline.yaml");
  auto config_inputs = generic(pipeline, good_log_.substr(0, 3000), 6);
  config_inputs[1].second = pipeline.substr(0, pipeline.find('[') + 2);  // inside a list: YAML cut short
  for (const auto& [what, bytes] : config_inputs)
    cases.push_back({"configuration (config)", what, [bytes = bytes](const fs::path& d) {
                       spit(d / "bad.yaml", bytes);
                       return bin("adit") + " config --config " + (d / "bad.yaml").string() + "|bad.yaml";
                     }, {}});
  auto launch_inputs = generic(kYaml, good_log_.substr(0, 3000), 7);
  launch_inputs[1].second = kYaml.substr(0, kYaml.find('[') + 6);
  for (const auto& [what, bytes] : launch_inputs)
    cases.push_back({"launch file (launch)", what, [bytes = bytes](const fs::path& d) {
                       spit(d / "bad.launch.yaml", bytes);
                       return bin("adit") + " launch " + (d / "bad.launch.yaml").string() + " --log-dir " +
                              (d / "runs").string() + " --duration 3|bad.launch.yaml";
                     }, {}});
  // adit-imu-bridge -o: the IMU text reader.
  const std::string imu = "10.000 0.1 0.2 0.3 0.0 0.0 9.81\n10.005 0.1 0.2 0.3 0.0 0.0 9.81\n";
  auto imu_inputs = generic(imu, good_bin_.substr(0, 3000), 8);
  imu_inputs[1].second = imu.substr(0, 40);  // the second line cut after its time
  imu_inputs.push_back({"wrong column count", "10.0 1 2 3\n10.1 1 2 3\n"});
  imu_inputs.push_back({"time beyond 2286", "1e300 0 0 0 0 0 9.8\n"});
  for (const auto& [what, bytes] : imu_inputs)
    cases.push_back({"IMU text (imu-bridge)", what, [bytes = bytes](const fs::path& d) {
                       spit(d / "imu.txt", bytes);
                       return bin("adit-imu-bridge") + " --path " + (d / "imu.txt").string() + " -o " +
                              (d / "out.lcmlog").string() + "|imu.txt";
                     }, {"out.lcmlog"}});
  // adit import pcap: not a capture, or a capture with no lidar packet in it. (A capture cut short is not here:
  // its whole records are imported and the cut counted, see ctest pcap.)
  const std::string pcap_header("\xD4\xC3\xB2\xA1\x02\x00\x04\x00\x00\x00\x00\x00\x00\x00\x00\x00"
                                "\xFF\xFF\x00\x00\x01\x00\x00\x00", 24);
  auto pcap_inputs = generic(pcap_header, kPcd, 7);
  pcap_inputs[1] = {"header cut short", pcap_header.substr(0, 13)};
  pcap_inputs.push_back({"header, no packet", pcap_header});
  pcap_inputs.push_back({"only an ARP frame", pcap_header + std::string("\0\0\0\0\0\0\0\0\x2A\0\0\0\x2A\0\0\0", 16) +
                                                  std::string(12, '\0') + "\x08\x06" + std::string(28, '\0')});
  for (const auto& [what, bytes] : pcap_inputs)
    cases.push_back({"pcap (import pcap)", what, [bytes = bytes](const fs::path& d) {
                       spit(d / "drive.pcap", bytes);
                       return bin("adit") + " import pcap " + (d / "drive.pcap").string() + " --sensor vlp16 -o " +
                              (d / "out.lcmlog").string() + "|drive.pcap";
                     }, {"out.lcmlog"}});
  for (const Case& c : cases) check(c);
  printTable();
}

}  // namespace
