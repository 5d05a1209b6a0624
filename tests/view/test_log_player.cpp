// adit view --log: the time slider's playback (play, pause, speed, seek back and forward) over a recorded log,
// driven by explicit wall-clock steps so every position and every event fed is exact.
#include "view/log_player.hpp"

#include "../io/temp_dir.hpp"
#include "runtime/lcm_log.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

namespace adit::view {
namespace {

constexpr std::int64_t kStartUtime = 1'700'000'000'000'000;  // the log's first event; positions count from it

// One event a second, t = 0..10 s, payload byte = its second.
std::string writeSecondsLog(const io::test::TempDir& dir) {
  const std::string path = dir.file("seconds.lcmlog");
  runtime::LogWriter w(path);
  for (int s = 0; s <= 10; ++s) w.write("TICK", {static_cast<std::uint8_t>(s)}, kStartUtime + s * 1'000'000);
  w.close();
  return path;
}

// What the session was fed since the last reset: the seconds of the events, in order.
struct Recorder : RunConsumer {
  std::vector<int> seconds;
  int resets = 0;
  void apply(const std::string& channel, const std::uint8_t* data, std::size_t size, std::int64_t utime) override {
    EXPECT_EQ(channel, "TICK");
    ASSERT_EQ(size, 1u);
    EXPECT_EQ(utime, kStartUtime + data[0] * 1'000'000);
    seconds.push_back(data[0]);
  }
  void reset() override {
    seconds.clear();
    ++resets;
  }
};

std::vector<int> upTo(int last) {
  std::vector<int> s;
  for (int i = 0; i <= last; ++i) s.push_back(i);
  return s;
}

class LogPlayerTest : public ::testing::Test {
 protected:
  io::test::TempDir dir;
  std::string log = writeSecondsLog(dir);
  Recorder session;
};

TEST_F(LogPlayerTest, PlayingMovesByWallTimeTimesSpeedAndFeedsEventsUpToThePosition) {
  LogPlayer player({log}, 1, true);
  EXPECT_DOUBLE_EQ(player.duration(), 10);
  player.advance(2.5, session);
  EXPECT_DOUBLE_EQ(player.position(), 2.5);
  EXPECT_EQ(session.seconds, upTo(2));
  player.advance(0.5, session);  // exactly on an event's time: it is fed
  EXPECT_EQ(session.seconds, upTo(3));
  ASSERT_TRUE(player.command("speed 4", session));
  player.advance(0.5, session);
  EXPECT_DOUBLE_EQ(player.position(), 5);
  EXPECT_EQ(session.seconds, upTo(5));
  EXPECT_EQ(session.resets, 0);
}

TEST_F(LogPlayerTest, SpeedOutsideItsRangeOrNotANumberIsRefusedAndKeepsTheOldSpeed) {
  LogPlayer player({log}, 2, true);
  for (const char* bad : {"speed 0.05", "speed 51", "speed -1", "speed fast", "speed"})
    EXPECT_FALSE(player.command(bad, session)) << bad;
  player.advance(1, session);
  EXPECT_DOUBLE_EQ(player.position(), 2);
  ASSERT_TRUE(player.command("speed 0.1", session));
  player.advance(10, session);
  EXPECT_DOUBLE_EQ(player.position(), 3);
  ASSERT_TRUE(player.command("speed 50", session));
  player.advance(0.1, session);
  EXPECT_DOUBLE_EQ(player.position(), 8);
}

TEST_F(LogPlayerTest, PausedPlayerStaysPutUntilPlay) {
  LogPlayer player({log}, 1, false);  // --paused
  player.advance(3, session);
  EXPECT_DOUBLE_EQ(player.position(), 0);
  EXPECT_TRUE(session.seconds.empty());
  ASSERT_TRUE(player.command("play", session));
  player.advance(1, session);
  EXPECT_EQ(session.seconds, upTo(1));
  ASSERT_TRUE(player.command("pause", session));
  player.advance(5, session);
  EXPECT_DOUBLE_EQ(player.position(), 1);
  EXPECT_EQ(session.seconds, upTo(1));
  EXPECT_EQ(session.resets, 0);
}

TEST_F(LogPlayerTest, SeekForwardFeedsTheSkippedEventsWithoutStartingOver) {
  LogPlayer player({log}, 1, false);
  player.advance(0, session);
  ASSERT_TRUE(player.command("seek 6.5", session));
  EXPECT_DOUBLE_EQ(player.position(), 6.5);
  EXPECT_EQ(session.seconds, upTo(6));  // the map is built from every event, none skipped
  EXPECT_EQ(session.resets, 0);
  player.advance(2, session);  // still paused: a seek does not start playing
  EXPECT_DOUBLE_EQ(player.position(), 6.5);
}

TEST_F(LogPlayerTest, SeekBackClearsTheSessionAndReplaysFromTheStart) {
  LogPlayer player({log}, 1, true);
  player.advance(7, session);
  ASSERT_EQ(session.seconds, upTo(7));
  ASSERT_TRUE(player.command("seek 2", session));
  EXPECT_EQ(session.resets, 1);
  EXPECT_DOUBLE_EQ(player.position(), 2);
  EXPECT_EQ(session.seconds, upTo(2));
  player.advance(1.5, session);  // and plays on from there
  EXPECT_EQ(session.seconds, upTo(3));
  ASSERT_TRUE(player.command("seek 3.5", session));  // the same place: nothing replayed
  EXPECT_EQ(session.resets, 1);
  EXPECT_EQ(session.seconds, upTo(3));
}

TEST_F(LogPlayerTest, SeekPastTheEndStopsAtTheEndAndNegativeOrMissingTimesAreRefused) {
  LogPlayer player({log}, 1, false);
  EXPECT_FALSE(player.command("seek -1", session));
  EXPECT_FALSE(player.command("seek", session));
  EXPECT_FALSE(player.command("rewind", session));
  ASSERT_TRUE(player.command("seek 99", session));
  EXPECT_DOUBLE_EQ(player.position(), 10);
  EXPECT_EQ(session.seconds, upTo(10));
  EXPECT_TRUE(player.atEnd());
}

TEST_F(LogPlayerTest, PlaybackStopsAtTheEndAndPlayThenStartsOver) {
  LogPlayer player({log}, 4, true);
  player.advance(5, session);  // 20 s of log asked for, 10 s there
  EXPECT_DOUBLE_EQ(player.position(), 10);
  EXPECT_EQ(session.seconds, upTo(10));
  EXPECT_TRUE(player.atEnd());
  EXPECT_NE(player.infoJson().find("\"playing\":false"), std::string::npos) << player.infoJson();
  ASSERT_TRUE(player.command("play", session));
  EXPECT_EQ(session.resets, 1);
  EXPECT_TRUE(session.seconds.empty());
  player.advance(0.5, session);
  EXPECT_EQ(session.seconds, upTo(2));
}

TEST_F(LogPlayerTest, InfoCarriesPositionDurationPlayingAndSpeedForThePage) {
  LogPlayer player({log}, 20, false);  // adit view --log run.lcmlog --speed 20 --paused
  EXPECT_EQ(player.infoJson(), R"("log":{"position_s":0,"duration_s":10,"playing":false,"speed":20})");
  ASSERT_TRUE(player.command("speed 2.5", session));
  ASSERT_TRUE(player.command("play", session));
  player.advance(1, session);
  EXPECT_EQ(player.infoJson(), R"("log":{"position_s":2.5,"duration_s":10,"playing":true,"speed":2.5})");
}

TEST_F(LogPlayerTest, TwoLogsPlayAsOneTimeline) {
  const std::string later = dir.file("later.lcmlog");
  {
    runtime::LogWriter w(later);
    w.write("TICK", {12}, kStartUtime + 12'000'000);
    w.close();
  }
  LogPlayer player({later, log}, 1, true);
  EXPECT_DOUBLE_EQ(player.duration(), 12);
  player.advance(11, session);
  EXPECT_EQ(session.seconds, upTo(10));
  player.advance(1, session);
  EXPECT_EQ(session.seconds.back(), 12);
}

TEST_F(LogPlayerTest, ALogWithoutEventsIsAnErrorAtStart) {
  dir.write("empty.lcmlog", "");
  EXPECT_THROW(LogPlayer({dir.file("empty.lcmlog")}, 1, true), std::runtime_error);
  EXPECT_THROW(LogPlayer({dir.file("missing.lcmlog")}, 1, true), std::runtime_error);
}

}  // namespace
}  // namespace adit::view
