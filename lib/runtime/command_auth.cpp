#include "runtime/command_auth.hpp"

#include "io/atomic_file.hpp"

#include <openssl/crypto.h>
#include <openssl/hmac.h>
#include <openssl/rand.h>

#include <sys/stat.h>
#include <fcntl.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace adit::runtime {
namespace {

constexpr char kDomain[] = "adit-command-v1";
constexpr std::size_t kNewKeyBytes = 32;

int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::string trimmed(const std::string& s) {
  std::size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return s.substr(b, e - b);
}

void appendField(std::vector<std::uint8_t>& out, const std::string& field) {
  out.insert(out.end(), field.begin(), field.end());
  out.push_back(0);
}

}  // namespace

CommandKey readCommandKey(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw std::runtime_error("command key '" + path + "': " + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw std::runtime_error("command key '" + path + "' is not a regular file");
  if ((st.st_mode & (S_IRWXG | S_IRWXO)) != 0)
    throw std::runtime_error("command key '" + path + "' may be read or written by other users (chmod 600 it)");
  if (st.st_size > 4096) throw std::runtime_error("command key '" + path + "' is too large to be a key");
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) throw std::runtime_error("command key '" + path + "' cannot be read");
  const std::string hex = trimmed(text.str());
  if (hex.size() % 2 != 0 || hex.size() < 32 || hex.size() > 128)
    throw std::runtime_error("command key '" + path + "' must hold 32 to 128 hex digits (an even count)");
  CommandKey key(hex.size() / 2);
  for (std::size_t i = 0; i < key.size(); ++i) {
    const int hi = hexValue(hex[2 * i]), lo = hexValue(hex[2 * i + 1]);
    if (hi < 0 || lo < 0) throw std::runtime_error("command key '" + path + "' holds a character that is not hex");
    key[i] = static_cast<std::uint8_t>(hi * 16 + lo);
  }
  return key;
}

void writeNewCommandKey(const std::string& path) {
  std::uint8_t key[kNewKeyBytes];
  if (RAND_bytes(key, sizeof key) != 1) throw std::runtime_error("no random bytes for a new command key");
  static const char digits[] = "0123456789abcdef";
  std::string hex;
  for (std::uint8_t b : key) {
    hex.push_back(digits[b >> 4]);
    hex.push_back(digits[b & 15]);
  }
  hex.push_back('\n');
  // Written to a private temp file, then linked to the name: link() fails if the name exists, so an existing
  // key is never replaced, and no reader ever sees a half-written one.
  const std::string temp = io::atomicTempPath(path);
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) throw std::runtime_error("cannot create '" + temp + "': " + std::strerror(errno));
  const bool written = ::write(fd, hex.data(), hex.size()) == static_cast<ssize_t>(hex.size()) && ::fsync(fd) == 0;
  ::close(fd);
  const int link_error = written && ::link(temp.c_str(), path.c_str()) == 0 ? 0 : errno;
  ::unlink(temp.c_str());
  if (!written) throw std::runtime_error("cannot write '" + temp + "'");
  if (link_error == EEXIST) throw std::runtime_error("'" + path + "' exists already (a key is never overwritten)");
  if (link_error != 0) throw std::runtime_error("cannot create '" + path + "': " + std::strerror(link_error));
}

CommandMac commandMac(const CommandKey& key, const std::string& channel, const std::string& command,
                      const std::string& argument, std::int64_t counter) {
  std::vector<std::uint8_t> message;
  appendField(message, kDomain);
  appendField(message, channel);
  appendField(message, command);
  appendField(message, argument);
  const auto u = static_cast<std::uint64_t>(counter);
  for (int shift = 56; shift >= 0; shift -= 8) message.push_back(static_cast<std::uint8_t>(u >> shift));
  CommandMac mac{};
  unsigned int length = 0;
  if (!HMAC(EVP_sha256(), key.data(), static_cast<int>(key.size()), message.data(), message.size(), mac.data(),
            &length) ||
      length != mac.size())
    throw std::runtime_error("HMAC-SHA256 failed");
  return mac;
}

std::string printableText(const std::string& text) {
  std::string out = text.substr(0, 80);
  for (char& c : out)
    if (c < 0x20 || c > 0x7e) c = '?';
  return text.size() > 80 ? out + "..." : out;
}

const char* counterName(CommandVerdict verdict) {
  switch (verdict) {
    case CommandVerdict::Authentic: return "commands_authentic";
    case CommandVerdict::Unsigned: return "command_unsigned";
    case CommandVerdict::BadMac: return "command_bad_mac";
    case CommandVerdict::Replayed: return "command_replayed";
    case CommandVerdict::Stale: return "command_stale";
  }
  return "command_unknown";
}

std::string describe(CommandVerdict verdict) {
  switch (verdict) {
    case CommandVerdict::Authentic: return "authentic";
    case CommandVerdict::Unsigned: return "not signed (this process requires signed commands: --command-key)";
    case CommandVerdict::BadMac: return "signature does not match (another key, or the command was altered)";
    case CommandVerdict::Replayed: return "counter not above the last accepted one (a replayed command)";
    case CommandVerdict::Stale: return "counter is not within the clock window (an old command, or a clock far off)";
  }
  return "unknown";
}

CommandGate::CommandGate(CommandKey key, double max_skew_s)
    : key_(std::move(key)), max_skew_us_(static_cast<std::int64_t>(max_skew_s * 1e6)) {}

CommandVerdict CommandGate::check(const std::string& channel, const std::string& command, const std::string& argument,
                                  std::int64_t counter, const std::vector<std::uint8_t>& mac,
                                  std::int64_t now_utime) {
  if (mac.empty()) return CommandVerdict::Unsigned;
  const CommandMac expected = commandMac(key_, channel, command, argument, counter);
  if (mac.size() != expected.size() || CRYPTO_memcmp(mac.data(), expected.data(), expected.size()) != 0)
    return CommandVerdict::BadMac;
  // Only an authentic counter is trusted for ordering: a forged one must not block the operator's next command.
  if (counter <= last_counter_) return CommandVerdict::Replayed;
  if (counter < now_utime - max_skew_us_ || counter > now_utime + max_skew_us_) return CommandVerdict::Stale;
  last_counter_ = counter;
  return CommandVerdict::Authentic;
}

}  // namespace adit::runtime
