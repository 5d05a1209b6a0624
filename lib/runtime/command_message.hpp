// A command message as every sender builds it (`adit command`, `adit view --allow-commands`): command_t for
// `channel`, signed when a key file is given, so a process that obeys only signed commands takes it.
#pragma once

#include <adit/command_t.hpp>

#include <cstdint>
#include <string>

namespace adit::runtime {

// `key_path` empty: unsigned. Otherwise the key is read (readCommandKey: throws std::runtime_error naming the
// problem) and the command signed with `counter` (the sender's wall clock in us: the receiver accepts it
// within its clock window and only above the last counter it accepted).
adit::command_t makeCommand(const std::string& channel, const std::string& command, const std::string& argument,
                            const std::string& key_path, std::int64_t counter);

}  // namespace adit::runtime
