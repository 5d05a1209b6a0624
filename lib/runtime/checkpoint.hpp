// Checkpoints: a stage's state in a small versioned binary file, written atomically (temp file + fsync +
// rename: a crash or a full disk leaves the previous checkpoint intact).
//
//   "ADITCKPT"  8 bytes magic
//   u32         format version (kCheckpointVersion)
//   string      kind ("odometry", "mapper", "loop_closer"; u64 length + bytes)
//   string      run id (the run folder's name: a checkpoint from another run is refused)
//   string      payload (the stage's own fields, lib/core/byte_codec.hpp)
//   u32         CRC-32 of everything before it
#pragma once

#include "core/crc32.hpp"

#include <cstdint>
#include <string>

namespace adit::runtime {

constexpr std::uint32_t kCheckpointVersion = 1;

// Throws io::WriteError (the previous file untouched) if it cannot be written.
void saveCheckpoint(const std::string& path, const std::string& kind, const std::string& run_id,
                    const std::string& payload);

struct LoadedCheckpoint {
  enum class Status { kMissing, kLoaded, kRefused };
  Status status = Status::kMissing;
  std::string payload;
  std::string error;  // why it was refused (truncated, checksum, version, kind, other run)
};

// Never throws.
LoadedCheckpoint loadCheckpoint(const std::string& path, const std::string& kind, const std::string& run_id);

using adit::crc32;  // core/crc32.hpp: the checkpoints' and record logs' checksum

}  // namespace adit::runtime
