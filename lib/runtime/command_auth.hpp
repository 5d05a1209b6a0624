// Signed commands. LCM over UDP multicast has no sender identity: any host that can reach the group can
// publish on MAPPER_COMMAND. With a shared key (a file only its owner can read), a process obeys a command
// only when it carries an HMAC-SHA256 of what it asks, made with that key, and a counter that is newer than
// every command accepted before and within a clock window (so a recorded command cannot be replayed later,
// even after the receiver restarts). Nothing here knows LCM: the node passes the fields it received.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace adit::runtime {

using CommandKey = std::vector<std::uint8_t>;
using CommandMac = std::array<std::uint8_t, 32>;

// Reads a key file: 32..128 hex digits (16..64 bytes), surrounding whitespace ignored. Refuses a file that
// other users may read or write (mode bits for group/other set), since then it is no secret. Throws
// std::runtime_error naming the problem.
CommandKey readCommandKey(const std::string& path);

// Writes a new random 32-byte key as hex to `path` with mode 0600. Never replaces an existing file (throws).
void writeNewCommandKey(const std::string& path);

// HMAC-SHA256 over "adit-command-v1", the channel, command and argument (each NUL-terminated) and the
// counter (8 bytes, big-endian). The channel is in it so a command cannot be moved to another channel.
CommandMac commandMac(const CommandKey& key, const std::string& channel, const std::string& command,
                      const std::string& argument, std::int64_t counter);

// What a command said, fit for one log line: at most 80 characters, anything unprintable as '?' (a command
// comes from anyone on the bus and must not write control sequences into the log).
std::string printableText(const std::string& text);

enum class CommandVerdict { Authentic, Unsigned, BadMac, Replayed, Stale };

// The STATUS counter a refused command is counted under ("command_unsigned", ...).
const char* counterName(CommandVerdict verdict);
std::string describe(CommandVerdict verdict);

// Decides, one command at a time, whether to obey. The sender's counter is its wall clock in microseconds:
// it must lie within `max_skew_s` of the receiver's clock and be above the last accepted counter.
class CommandGate {
 public:
  explicit CommandGate(CommandKey key, double max_skew_s = 30.0);

  CommandVerdict check(const std::string& channel, const std::string& command, const std::string& argument,
                       std::int64_t counter, const std::vector<std::uint8_t>& mac, std::int64_t now_utime);

 private:
  CommandKey key_;
  std::int64_t max_skew_us_;
  std::int64_t last_counter_ = INT64_MIN;
};

}  // namespace adit::runtime
