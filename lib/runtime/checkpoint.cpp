#include "runtime/checkpoint.hpp"

#include "core/byte_codec.hpp"
#include "io/atomic_file.hpp"

#include <cstring>
#include <fstream>
#include <iterator>

namespace adit::runtime {
namespace {

constexpr char kMagic[8] = {'A', 'D', 'I', 'T', 'C', 'K', 'P', 'T'};
// A checkpoint holds at most the loop closer's keyframes (~60 kB each at 0.2 m): 2 GB is far beyond any run.
constexpr std::uintmax_t kMaxCheckpointBytes = 2ull << 30;

}  // namespace

void saveCheckpoint(const std::string& path, const std::string& kind, const std::string& run_id,
                    const std::string& payload) {
  ByteWriter w;
  for (const char c : kMagic) w.put<char>(c);
  w.put<std::uint32_t>(kCheckpointVersion);
  w.putString(kind);
  w.putString(run_id);
  w.putString(payload);
  std::string bytes = w.bytes();
  const std::uint32_t crc = crc32(bytes.data(), bytes.size());
  bytes.append(reinterpret_cast<const char*>(&crc), sizeof(crc));
  io::writeFileAtomically(path, bytes);
}

LoadedCheckpoint loadCheckpoint(const std::string& path, const std::string& kind, const std::string& run_id) {
  LoadedCheckpoint out;
  std::ifstream in(path, std::ios::binary);
  if (!in) return out;  // missing: a fresh start, not an error
  out.status = LoadedCheckpoint::Status::kRefused;
  in.seekg(0, std::ios::end);
  const auto size = static_cast<std::uintmax_t>(in.tellg());
  in.seekg(0);
  if (!in || size > kMaxCheckpointBytes) {
    out.error = path + ": unreadable or larger than 2 GB";
    return out;
  }
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (bytes.size() < sizeof(kMagic) + 4 + 4 || bytes.compare(0, sizeof(kMagic), kMagic, sizeof(kMagic)) != 0) {
    out.error = path + ": not an adit checkpoint (" + std::to_string(bytes.size()) + " bytes)";
    return out;
  }
  ByteReader r(bytes.data(), bytes.size() - 4);
  for (std::size_t i = 0; i < sizeof(kMagic); ++i) r.get<char>();
  const auto version = r.get<std::uint32_t>();
  const std::string file_kind = r.getString();
  const std::string file_run = r.getString();
  std::string payload = r.getString();
  std::uint32_t stored_crc = 0;
  std::memcpy(&stored_crc, bytes.data() + bytes.size() - 4, 4);
  if (!r.ok() || !r.atEnd()) {
    out.error = path + ": truncated or malformed checkpoint";
  } else if (stored_crc != crc32(bytes.data(), bytes.size() - 4)) {
    out.error = path + ": checksum mismatch (corrupt or truncated checkpoint)";
  } else if (version != kCheckpointVersion) {
    out.error = path + ": checkpoint format version " + std::to_string(version) + ", this build reads " +
                std::to_string(kCheckpointVersion);
  } else if (file_kind != kind) {
    out.error = path + ": a '" + file_kind + "' checkpoint, expected '" + kind + "'";
  } else if (file_run != run_id) {
    out.error = path + ": checkpoint of run '" + file_run + "', this run is '" + run_id + "'";
  } else {
    out.status = LoadedCheckpoint::Status::kLoaded;
    out.payload = std::move(payload);
  }
  return out;
}

}  // namespace adit::runtime
