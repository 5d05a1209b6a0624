// LCM log files: round trip, and corrupt or truncated logs skipped with counts instead of failing.
#include "runtime/lcm_log.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
using adit::runtime::LogEvent;
using adit::runtime::LogReader;
using adit::runtime::LogWriter;

namespace {

fs::path tempPath(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("adit_test_lcm_log_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

std::vector<std::uint8_t> payload(int i) { return std::vector<std::uint8_t>(static_cast<std::size_t>(10 + i), static_cast<std::uint8_t>(i)); }

void writeLog(const fs::path& path, int n) {
  LogWriter w(path.string());
  for (int i = 0; i < n; ++i) w.write(i % 2 ? "IMU" : "LIDAR_POINTS", payload(i), 1000 * i);
  w.close();
}

std::vector<LogEvent> readAll(LogReader& r) {
  std::vector<LogEvent> out;
  LogEvent e;
  while (r.next(e)) out.push_back(e);
  return out;
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), {}};
}

}  // namespace

TEST(LcmLog, RoundTripKeepsChannelsTimesAndPayloads) {
  const auto path = tempPath("round.lcmlog");
  writeLog(path, 5);
  EXPECT_FALSE(fs::exists(path.string() + ".tmp." + std::to_string(::getpid())));  // renamed into place
  LogReader r(path.string());
  const auto events = readAll(r);
  ASSERT_EQ(events.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(events[i].event_number, i);
    EXPECT_EQ(events[i].timestamp, 1000 * i);
    EXPECT_EQ(events[i].channel, i % 2 ? "IMU" : "LIDAR_POINTS");
    EXPECT_EQ(events[i].data, payload(i));
  }
  EXPECT_EQ(r.corruptFrames(), 0);
  EXPECT_FALSE(r.truncated());
}

TEST(LcmLog, CorruptFrameInTheMiddleIsSkippedAndCounted) {
  const auto path = tempPath("corrupt.lcmlog");
  writeLog(path, 5);
  std::string bytes = slurp(path);
  // Frame 2 starts after frames 0 and 1: header 28 bytes + channel + data each.
  const std::size_t frame2 = (28 + 12 + 10) + (28 + 3 + 11);
  bytes[frame2 + 22] = '\x7f';  // channel length of frame 2 becomes absurd
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  LogReader r(path.string());
  const auto events = readAll(r);
  ASSERT_EQ(events.size(), 4u);
  EXPECT_EQ(events[2].event_number, 3);  // 0, 1, (2 lost), 3, 4
  EXPECT_EQ(r.corruptFrames(), 1);
}

TEST(LcmLog, TruncatedTailEndsTheLogWithAFlag) {
  const auto path = tempPath("truncated.lcmlog");
  writeLog(path, 5);
  const std::string bytes = slurp(path);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() - 7);
  LogReader r(path.string());
  EXPECT_EQ(readAll(r).size(), 4u);
  EXPECT_TRUE(r.truncated());
}

TEST(LcmLog, GarbageFileYieldsNothingAndDoesNotThrow) {
  const auto path = tempPath("garbage.lcmlog");
  std::string junk(5000, '\0');
  for (std::size_t i = 0; i < junk.size(); ++i) junk[i] = static_cast<char>((i * 7919) % 251);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << junk;
  LogReader r(path.string());
  EXPECT_TRUE(readAll(r).empty());
}

TEST(LcmLog, MissingFileThrowsAClearError) {
  try {
    LogReader r("/nonexistent/adit.lcmlog");
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/adit.lcmlog"), std::string::npos);
  }
}

// A writer abandoned by an exception (a replay that failed half way) leaves nothing behind: no half log
// under the final name (it used to commit it), no temp file.
// `-o /dev/null` or a named pipe: written in place; renaming the finished log over it would replace it with
// a regular file (as root, /dev/null itself). A pipe here, which is safe to get wrong.
TEST(LcmLog, APipeIsWrittenInPlaceAndStaysAPipe) {
  const fs::path fifo = tempPath("pipe.lcmlog");
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // The reading end first (non-blocking, so a wrong rename fails the test instead of hanging it).
  const int fd = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(fd, 0);
  {
    LogWriter w(fifo.string());
    w.write("A", payload(1), 1);
    w.close();
  }
  char buf[256];
  const ssize_t got = ::read(fd, buf, sizeof buf);
  ::close(fd);
  EXPECT_EQ(got, static_cast<ssize_t>(28 + 1 + payload(1).size())) << "one event: header, channel, payload";
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_FALSE(fs::exists(fifo.string() + ".tmp." + std::to_string(::getpid())));
  fs::remove(fifo);
}

TEST(LcmLog, WriterDestroyedWithoutCloseLeavesNothing) {
  const auto path = tempPath("abandoned.lcmlog");
  fs::remove(path);
  {
    LogWriter w(path.string());
    w.write("IMU", payload(3), 1);
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path.string() + ".tmp." + std::to_string(::getpid())));
}

// A frame header announcing far more bytes than the file holds allocates nothing and ends the log.
TEST(LcmLog, LengthFieldsBeyondTheFileAreNotAllocated) {
  const auto path = tempPath("liar.lcmlog");
  const unsigned char frame[28] = {0xED, 0xA1, 0xDA, 0x01, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1,
                                   0, 0, 0, 3, 0x1F, 0xFF, 0xFF, 0xFF};  // data length 512 MB
  std::ofstream(path, std::ios::binary | std::ios::trunc) << std::string(reinterpret_cast<const char*>(frame), 28) << "IMU";
  LogReader r(path.string());
  EXPECT_TRUE(readAll(r).empty());
  EXPECT_TRUE(r.truncated());
  EXPECT_THROW(LogReader(fs::temp_directory_path().string()), std::runtime_error);  // a folder is not a log
}

// Disk full: every write is checked, the error names the log, and neither the log nor its temp file stays.
// The temp file is pointed at /dev/full (writes fail with ENOSPC), which needs no privilege.
TEST(LcmLog, DiskFullIsAnErrorAndLeavesNoFile) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const auto path = tempPath("full.lcmlog");
  fs::remove(path);
  const std::string tmp = path.string() + ".tmp." + std::to_string(::getpid());
  fs::remove(tmp);
  fs::create_symlink("/dev/full", tmp);
  try {
    LogWriter w(path.string());
    for (int i = 0; i < 2000; ++i) w.write("LIDAR_POINTS", payload(100), i);  // beyond stdio's buffer
    w.close();
    FAIL() << "expected a write error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("No space left on device"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::is_symlink(tmp));
}
