// Signed commands: the MAC is the documented HMAC-SHA256 (a vector computed independently), and the gate
// obeys only a command signed with the key, not altered, not replayed, and within the clock window.
#include "runtime/command_auth.hpp"
#include "runtime/command_message.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace adit::runtime {
namespace {

namespace fs = std::filesystem;

CommandKey testKey() {
  CommandKey key(32);
  for (std::size_t i = 0; i < key.size(); ++i) key[i] = static_cast<std::uint8_t>(i);
  return key;
}

std::vector<std::uint8_t> macOf(const CommandKey& key, const std::string& argument, std::int64_t counter,
                                const std::string& channel = "MAPPER_COMMAND") {
  const CommandMac mac = commandMac(key, channel, "save_map", argument, counter);
  return {mac.begin(), mac.end()};
}

fs::path freshDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("adit_command_auth_" + name + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void writeFile(const fs::path& path, const std::string& text, mode_t mode) {
  std::ofstream(path) << text;
  ::chmod(path.c_str(), mode);
}

constexpr std::int64_t kNow = 1700000000123456;

TEST(CommandAuth, MacIsHmacSha256OverTheDocumentedMessage) {
  // python3: hmac.new(bytes(range(32)), b'adit-command-v1\0MAPPER_COMMAND\0save_map\0night_shift\0' +
  //          struct.pack('>q', 1700000000123456), hashlib.sha256).hexdigest()
  const CommandMac mac = commandMac(testKey(), "MAPPER_COMMAND", "save_map", "night_shift", kNow);
  std::string hex;
  for (std::uint8_t b : mac) hex += fmt::format("{:02x}", b);
  EXPECT_EQ(hex, "bc2cb744a5e2bc948b56673f6a1f0f87bdc93bc9acb7f22cf911df787ff50827");
}

TEST(CommandAuth, GateObeysOnlyFreshAuthenticCommands) {
  CommandGate gate(testKey());
  const CommandKey other(32, 7);
  EXPECT_EQ(gate.check("MAPPER_COMMAND", "save_map", "a", 0, {}, kNow), CommandVerdict::Unsigned);
  EXPECT_EQ(gate.check("MAPPER_COMMAND", "save_map", "a", kNow, macOf(other, "a", kNow), kNow), CommandVerdict::BadMac);
  // Altered after signing: another argument, counter or channel than the one signed.
  EXPECT_EQ(gate.check("MAPPER_COMMAND", "save_map", "b", kNow, macOf(testKey(), "a", kNow), kNow), CommandVerdict::BadMac);
  EXPECT_EQ(gate.check("MAPPER_COMMAND", "save_map", "a", kNow + 1, macOf(testKey(), "a", kNow), kNow),
            CommandVerdict::BadMac);
  EXPECT_EQ(gate.check("OTHER_COMMAND", "save_map", "a", kNow, macOf(testKey(), "a", kNow), kNow), CommandVerdict::BadMac);
  std::vector<std::uint8_t> short_mac = macOf(testKey(), "a", kNow);
  short_mac.pop_back();
  EXPECT_EQ(gate.check("MAPPER_COMMAND", "save_map", "a", kNow, short_mac, kNow), CommandVerdict::BadMac);

  EXPECT_EQ(gate.check("MAPPER_COMMAND", "save_map", "a", kNow, macOf(testKey(), "a", kNow), kNow + 1'000'000),
            CommandVerdict::Authentic);
  // The same command again (a recording of it) and an older one are replays.
  EXPECT_EQ(gate.check("MAPPER_COMMAND", "save_map", "a", kNow, macOf(testKey(), "a", kNow), kNow + 2'000'000),
            CommandVerdict::Replayed);
  EXPECT_EQ(gate.check("MAPPER_COMMAND", "save_map", "a", kNow - 5, macOf(testKey(), "a", kNow - 5), kNow),
            CommandVerdict::Replayed);
  // Newer but outside the 30 s window on either side: a command kept for later, or a sender's clock far off.
  const std::int64_t late = kNow + 10'000'000;
  EXPECT_EQ(gate.check("MAPPER_COMMAND", "save_map", "a", late, macOf(testKey(), "a", late), late + 31'000'000),
            CommandVerdict::Stale);
  EXPECT_EQ(gate.check("MAPPER_COMMAND", "save_map", "a", late, macOf(testKey(), "a", late), late - 31'000'000),
            CommandVerdict::Stale);
  // A refused command does not advance the counter: the operator's next command still works.
  EXPECT_EQ(gate.check("MAPPER_COMMAND", "save_map", "a", late, macOf(testKey(), "a", late), late + 1000),
            CommandVerdict::Authentic);
  EXPECT_STREQ(counterName(CommandVerdict::Replayed), "command_replayed");
}

// What `adit command` and `adit view --allow-commands` send: signed with the key file when there is one.
TEST(CommandAuth, SendersBuildCommandsTheGateObeys) {
  const fs::path dir = freshDir("sender");
  const fs::path key = dir / "operator.key";
  writeNewCommandKey(key.string());
  CommandGate gate(readCommandKey(key.string()));
  const adit::command_t signed_command = makeCommand("MAPPER_COMMAND", "save_map", "shift_2", key.string(), kNow);
  EXPECT_EQ(signed_command.command, "save_map");
  EXPECT_EQ(signed_command.argument, "shift_2");
  EXPECT_EQ(signed_command.mac_size, 32);
  EXPECT_EQ(gate.check("MAPPER_COMMAND", signed_command.command, signed_command.argument, signed_command.counter,
                       signed_command.mac, kNow),
            CommandVerdict::Authentic);
  const adit::command_t plain = makeCommand("MAPPER_COMMAND", "save_map", "shift_3", "", kNow + 1);
  EXPECT_EQ(plain.mac_size, 0);
  EXPECT_EQ(gate.check("MAPPER_COMMAND", plain.command, plain.argument, plain.counter, plain.mac, kNow + 1),
            CommandVerdict::Unsigned);
  EXPECT_THROW(makeCommand("MAPPER_COMMAND", "save_map", "x", (dir / "missing.key").string(), kNow), std::runtime_error);
}

TEST(CommandAuth, KeyFilesMustBePrivateHexAndAreNeverOverwritten) {
  const fs::path dir = freshDir("keys");
  const fs::path key = dir / "operator.key";
  writeNewCommandKey(key.string());
  struct stat st {};
  ASSERT_EQ(::stat(key.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  const CommandKey read = readCommandKey(key.string());
  EXPECT_EQ(read.size(), 32u);
  EXPECT_THROW(writeNewCommandKey(key.string()), std::runtime_error);
  EXPECT_EQ(readCommandKey(key.string()), read);  // untouched by the refused keygen
  // A second key is another key.
  writeNewCommandKey((dir / "second.key").string());
  EXPECT_NE(readCommandKey((dir / "second.key").string()), read);

  const std::string hex32(64, 'a');
  writeFile(dir / "readable.key", hex32, 0644);
  EXPECT_THROW(readCommandKey((dir / "readable.key").string()), std::runtime_error);
  writeFile(dir / "short.key", std::string(30, 'a'), 0600);
  EXPECT_THROW(readCommandKey((dir / "short.key").string()), std::runtime_error);
  writeFile(dir / "odd.key", std::string(33, 'a'), 0600);
  EXPECT_THROW(readCommandKey((dir / "odd.key").string()), std::runtime_error);
  writeFile(dir / "nothex.key", std::string(62, 'a') + "zz", 0600);
  EXPECT_THROW(readCommandKey((dir / "nothex.key").string()), std::runtime_error);
  writeFile(dir / "good.key", "  " + hex32 + "\n", 0600);
  EXPECT_EQ(readCommandKey((dir / "good.key").string()), CommandKey(32, 0xaa));
  EXPECT_THROW(readCommandKey((dir / "missing.key").string()), std::runtime_error);
  EXPECT_THROW(readCommandKey(dir.string()), std::runtime_error);
  fs::remove_all(dir);
}

TEST(CommandAuth, PrintableTextKeepsLogLinesPlain) {
  EXPECT_EQ(printableText("save\x1b[2J\n"), "save?[2J?");
  EXPECT_EQ(printableText(std::string(100, 'x')), std::string(80, 'x') + "...");
}

}  // namespace
}  // namespace adit::runtime
