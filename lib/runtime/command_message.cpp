#include "runtime/command_message.hpp"

#include "runtime/command_auth.hpp"

namespace adit::runtime {

adit::command_t makeCommand(const std::string& channel, const std::string& command, const std::string& argument,
                            const std::string& key_path, std::int64_t counter) {
  adit::command_t c{};
  c.header.utime = counter;
  c.header.seq = 0;
  c.command = command;
  c.argument = argument;
  if (key_path.empty()) return c;
  const CommandMac mac = commandMac(readCommandKey(key_path), channel, command, argument, counter);
  c.counter = counter;
  c.mac.assign(mac.begin(), mac.end());
  c.mac_size = static_cast<std::int32_t>(c.mac.size());
  return c;
}

}  // namespace adit::runtime
