// The N100 serial IMU: FDILink frames (CRCs against their published check values, resynchronisation after
// noise, split and corrupt frames), the device-clock synchronisation against a simulated clock with drift,
// jitter and a fixed delay, and the whole serial source through a pseudo-terminal, including an unplug.
#include "drivers/clock_sync.hpp"
#include "drivers/fdilink.hpp"
#include "drivers/serial_imu_source.hpp"
#include "msg/convert.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>
#include <thread>

namespace adit::drivers {
namespace {

std::vector<std::uint8_t> bytesOf(const char* text) { return {text, text + std::strlen(text)}; }

FdiImu imuAt(int k) {
  FdiImu imu;
  imu.device_us = 5'000'000 + k * 5000;  // 200 Hz
  imu.gyro = {0.01 * k, -0.02, 0.5};
  imu.accel = {0.1, 0.2, 9.81};
  return imu;
}

std::vector<std::uint8_t> imuFrame(int k) {
  return encodeFdiFrame(kFdiImuPacket, static_cast<std::uint8_t>(k), encodeFdiImu(imuAt(k)));
}

TEST(FdiLink, CrcsMatchTheirCatalogueCheckValues) {
  const auto check = bytesOf("123456789");
  EXPECT_EQ(fdiCrc8(check.data(), check.size()), 0xA1);      // CRC-8/MAXIM
  EXPECT_EQ(fdiCrc16(check.data(), check.size()), 0x31C3);   // CRC-16/XMODEM
}

TEST(FdiLink, FramesSplitAnywhereAndNoiseBetweenThemAreFound) {
  std::vector<std::uint8_t> stream = bytesOf("garbage\xFC\xFD noise");
  for (int k = 0; k < 20; ++k) {
    const auto f = imuFrame(k);
    stream.insert(stream.end(), f.begin(), f.end());
    if (k % 3 == 0) stream.push_back(0xFC);  // a lone start byte between frames
  }
  for (std::size_t chunk : {std::size_t{1}, std::size_t{7}, std::size_t{64}, stream.size()}) {
    FdiLinkParser parser;
    std::vector<FdiImu> got;
    for (std::size_t i = 0; i < stream.size(); i += chunk)
      parser.push(stream.data() + i, std::min(chunk, stream.size() - i), [&](const FdiFrame& f) {
        if (auto imu = decodeFdiImu(f.payload)) got.push_back(*imu);
      });
    ASSERT_EQ(got.size(), 20u) << "chunk " << chunk;
    for (int k = 0; k < 20; ++k) {
      EXPECT_EQ(got[k].device_us, imuAt(k).device_us);
      EXPECT_NEAR(got[k].gyro.x(), imuAt(k).gyro.x(), 1e-6);
      EXPECT_NEAR(got[k].accel.z(), 9.81, 1e-5);
    }
    EXPECT_EQ(parser.counters().at("frames"), 20);
    EXPECT_GT(parser.counters().at("skipped_bytes"), 10);
  }
}

TEST(FdiLink, CorruptFramesAreCountedAndTheNextOneIsFound) {
  std::vector<std::uint8_t> stream;
  const auto append = [&](std::vector<std::uint8_t> f) { stream.insert(stream.end(), f.begin(), f.end()); };
  append(imuFrame(0));
  auto bad_header = imuFrame(1);
  bad_header[2] ^= 0x01;  // length: CRC8 fails
  append(bad_header);
  auto bad_payload = imuFrame(2);
  bad_payload[20] ^= 0x40;  // CRC16 fails
  append(bad_payload);
  auto bad_tail = imuFrame(3);
  bad_tail.back() = 0x00;
  append(bad_tail);
  auto cut = imuFrame(4);
  cut.resize(30);  // a frame cut short by a reset
  append(cut);
  append(imuFrame(5));
  append(imuFrame(6));
  FdiLinkParser parser;
  std::vector<std::uint8_t> serials;
  parser.push(stream.data(), stream.size(), [&](const FdiFrame& f) { serials.push_back(f.serial); });
  EXPECT_EQ(serials, (std::vector<std::uint8_t>{0, 5, 6}));
  const auto& c = parser.counters();
  EXPECT_GE(c.at("crc8_error"), 1);
  EXPECT_GE(c.at("crc16_error"), 1);
  EXPECT_GE(c.at("bad_tail"), 1);
  EXPECT_EQ(c.at("lost_frames"), 4);  // serials 1-4 never arrived whole
}

TEST(FdiLink, PayloadsOfTheWrongSizeOrNotFiniteAreRefused) {
  auto p = encodeFdiImu(imuAt(0));
  EXPECT_TRUE(decodeFdiImu(p));
  EXPECT_FALSE(decodeFdiImu({p.begin(), p.end() - 1}));
  const float nan = std::nanf("");
  std::memcpy(p.data() + 4, &nan, 4);
  EXPECT_FALSE(decodeFdiImu(p));
  FdiAhrs ahrs;
  ahrs.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()));
  const auto decoded = decodeFdiAhrs(encodeFdiAhrs(ahrs));
  ASSERT_TRUE(decoded);
  EXPECT_NEAR(decoded->orientation.angularDistance(ahrs.orientation), 0, 1e-6);
  auto not_unit = encodeFdiAhrs(ahrs);
  const float two = 2.0f;
  std::memcpy(not_unit.data() + 24, &two, 4);
  EXPECT_FALSE(decodeFdiAhrs(not_unit));
}

// The device's counter runs 50 ppm fast from an unknown origin; each sample reaches the host 2 ms later
// (fixed) plus jitter (exponential, mean 1.5 ms, and 3 % of samples 10-40 ms late). The synchronised stamp
// must be the sampling instant on the host clock to within 1 ms once a few seconds have passed.
TEST(ClockSync, ConvergesToWithinAMillisecondUnderJitterAndDrift) {
  ClockSyncConfig config;
  config.transport_delay_s = 0.002;
  DeviceClockSync sync(config);
  std::mt19937 rng(7);
  std::exponential_distribution<double> jitter(1.0 / 1500.0);
  std::uniform_real_distribution<double> uniform(0, 1);
  const double host_origin = 1.8e15, drift = 50e-6;
  double worst_after_5s = 0;
  for (int k = 0; k < 200 * 60; ++k) {
    const std::int64_t device_us = 123'456'789 + k * 5000LL;
    const double true_host = host_origin + (device_us - 123'456'789) * (1.0 - drift);
    double delay = 2000 + jitter(rng);
    if (uniform(rng) < 0.03) delay += 10'000 + 30'000 * uniform(rng);
    const std::int64_t stamp = sync.stamp(device_us, static_cast<std::int64_t>(true_host + delay));
    if (k >= 200 * 5) worst_after_5s = std::max(worst_after_5s, std::abs(stamp - true_host));
  }
  EXPECT_LT(worst_after_5s, 1000.0) << "us";
  EXPECT_NEAR(sync.driftPpm(), -50.0, 5.0);
}

TEST(ClockSync, FollowsADeviceClockResetAndNeverGoesBackwards) {
  DeviceClockSync sync;
  std::int64_t last = 0;
  for (int k = 0; k < 2000; ++k) {
    // At k = 1000 the device restarts its counter from 0; the host clock runs on.
    const std::int64_t device_us = k < 1000 ? 9'000'000 + k * 5000LL : (k - 1000) * 5000LL;
    const std::int64_t host_us = 1'000'000'000 + k * 5000LL + 1000;
    const std::int64_t stamp = sync.stamp(device_us, host_us);
    if (k > 0) {
      EXPECT_GT(stamp, last) << k;
    }
    last = stamp;
    if (k >= 1010) {
      EXPECT_NEAR(static_cast<double>(stamp), host_us - 1000.0, 1000.0) << k;
    }
  }
  EXPECT_EQ(sync.clockJumps(), 1);
}

// A pseudo-terminal stands in for the USB serial device: the test writes to the master side, the source
// reads the slave through a symlink (as udev's /dev/serial/by-id links), which an "unplug" re-points.
// The test keeps the slave side open too (a terminal whose last opener closed it drops its input when it is
// opened again) and starts it raw, since the source opens it only when it first reads.
struct FakeDevice {
  int master = -1;
  int slave_fd = -1;
  std::string slave;
  FakeDevice() {
    char name[128];
    termios raw{};
    ::cfmakeraw(&raw);  // as a serial line is: no line editing of what the test writes before the source opens it
    EXPECT_EQ(::openpty(&master, &slave_fd, name, &raw, nullptr), 0);
    slave = name;
  }
  ~FakeDevice() { unplug(); }
  void write(const std::vector<std::uint8_t>& bytes) const {
    ASSERT_EQ(::write(master, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
  }
  void unplug() {
    if (master >= 0) ::close(master);
    if (slave_fd >= 0) ::close(slave_fd);
    master = slave_fd = -1;
  }
};

bool nextSample(runtime::MessageSource& source, ImuSample& sample) {
  runtime::OutgoingMessage m;
  if (!source.next(m)) return false;
  adit::imu_t msg;
  if (msg.decode(m.data.data(), 0, static_cast<int>(m.data.size())) < 0) return false;
  sample = msg::fromMessage(msg);
  return true;
}

TEST(SerialImuSource, ReadsN100FramesFromADeviceAndReopensItAfterAnUnplug) {
  namespace fs = std::filesystem;
  const fs::path link = fs::temp_directory_path() / ("adit_imu_" + std::to_string(::getpid()));
  fs::remove(link);
  auto device = std::make_unique<FakeDevice>();
  fs::create_symlink(device->slave, link);

  SerialImuConfig config;
  config.device = link.string();
  config.clock = "host";
  config.reopen_period_s = 0.2;
  std::int64_t host_us = 0;
  int polls_without_data = 0;
  // Stops the source if nothing arrives for ~5 s of polling (a hung test fails instead of hanging).
  auto source = makeSerialImuSource(config, [&] { return ++polls_without_data > 50; },
                                    [&] { return host_us += 1000; });
  ImuSample s;
  // Good frames split across writes, with noise and an AHRS frame in between.
  FdiAhrs ahrs;
  ahrs.device_us = imuAt(0).device_us;
  ahrs.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  std::vector<std::uint8_t> bytes = encodeFdiFrame(kFdiAhrsPacket, 0, encodeFdiAhrs(ahrs));
  for (int k = 0; k < 5; ++k) {
    const auto f = imuFrame(k);
    bytes.insert(bytes.end(), f.begin(), f.end());
  }
  auto corrupt = imuFrame(5);
  corrupt[30] ^= 0xFF;
  bytes.insert(bytes.end(), corrupt.begin(), corrupt.end());
  const auto last = imuFrame(6);
  bytes.insert(bytes.end(), last.begin(), last.end());
  device->write({bytes.begin(), bytes.begin() + 50});
  device->write({bytes.begin() + 50, bytes.end()});
  std::vector<ImuSample> got;
  for (int i = 0; i < 6 && nextSample(*source, s); ++i) {
    got.push_back(s);
    polls_without_data = 0;
  }
  ASSERT_EQ(got.size(), 6u);
  EXPECT_NEAR(got[0].gyro.z(), 0.5, 1e-6);
  EXPECT_NEAR(got[5].gyro.x(), 0.06, 1e-6) << "the corrupt frame 5 is skipped, frame 6 follows";
  ASSERT_TRUE(got[0].orientation.has_value());
  EXPECT_NEAR(got[0].orientation->angularDistance(ahrs.orientation), 0, 1e-6);
  EXPECT_EQ(source->health().counters.at("crc16_error"), 1);

  // Unplugged: the device vanishes; it comes back under another name that the link now points to.
  device->unplug();
  auto replugged = std::make_unique<FakeDevice>();
  fs::remove(link);
  fs::create_symlink(replugged->slave, link);
  std::atomic<bool> resumed_reading{false};
  std::thread writer([&] {
    for (int tries = 0; tries < 40 && !resumed_reading; ++tries) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      replugged->write(imuFrame(7));
    }
  });
  polls_without_data = 0;
  const bool resumed = nextSample(*source, s);
  resumed_reading = true;
  writer.join();
  EXPECT_TRUE(resumed);
  EXPECT_NEAR(s.gyro.x(), 0.07, 1e-6);
  EXPECT_EQ(source->health().counters.at("device_lost"), 1);
  EXPECT_EQ(source->health().counters.at("reopened"), 1);
  fs::remove(link);
}

TEST(SerialImuSource, TextProtocolLinesWithNoiseAndDeviceTime) {
  FakeDevice device;
  SerialImuConfig config;
  config.device = device.slave;
  config.protocol = "text";
  config.transport_delay_s = 0;
  int polls = 0;
  std::int64_t host_us = 1'700'000'000'000'000;
  auto source = makeSerialImuSource(config, [&] { return ++polls > 50; }, [&] { return host_us += 5000; });
  device.write(bytesOf("# N100 text\r\n0.000 0.1 0.2 0.3 0 0 9.8\r\nnot a line\r\n0.005 0.1 0.2 0.3 0 0 9.8\n"
                       "0.010 0.1 0.2 0.3 0 0 9.8\n"));
  ImuSample a, b, c;
  ASSERT_TRUE(nextSample(*source, a));
  ASSERT_TRUE(nextSample(*source, b));
  ASSERT_TRUE(nextSample(*source, c));
  EXPECT_NEAR(a.gyro.y(), 0.2, 1e-9);
  EXPECT_GT(b.utime, a.utime);
  EXPECT_GT(a.utime, 1'700'000'000'000'000) << "stamped on the host clock, not device seconds";
  EXPECT_EQ(source->health().counters.at("bad_line"), 1);
}

TEST(SerialImuSource, BadSettingsAreRefused) {
  SerialImuConfig config;
  config.protocol = "nmea";
  EXPECT_THROW(makeSerialImuSource(config), std::invalid_argument);
  config.protocol = "n100";
  config.baud = 12345;
  EXPECT_THROW(makeSerialImuSource(config), std::invalid_argument);
}

}  // namespace
}  // namespace adit::drivers
