#include "runtime/record_log.hpp"

#include "core/byte_codec.hpp"
#include "runtime/checkpoint.hpp"

#include <unistd.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace adit::runtime {
namespace {

constexpr char kMagic[8] = {'A', 'D', 'I', 'T', 'R', 'L', 'O', 'G'};
constexpr std::uint32_t kVersion = 1;

std::string header(const std::string& kind, const std::string& run_id) {
  ByteWriter w;
  for (const char c : kMagic) w.put<char>(c);
  w.put<std::uint32_t>(kVersion);
  w.putString(kind);
  w.putString(run_id);
  return w.bytes();
}

// Byte offset after the header and the first `n` valid records (or after all valid ones); the records.
struct Scan {
  std::size_t end = 0;
  std::vector<std::string> records;
  std::string error;
};

Scan scan(const std::string& bytes, const std::string& kind, const std::string& run_id, std::size_t max_records) {
  Scan s;
  ByteReader r(bytes);
  for (const char c : kMagic)
    if (r.get<char>() != c) r.fail();
  const auto version = r.get<std::uint32_t>();
  const std::string file_kind = r.getString(), file_run = r.getString();
  if (!r.ok()) s.error = "not an adit record log";
  else if (version != kVersion) s.error = "record log version " + std::to_string(version);
  else if (file_kind != kind) s.error = "a '" + file_kind + "' record log, expected '" + kind + "'";
  else if (file_run != run_id) s.error = "record log of run '" + file_run + "', this run is '" + run_id + "'";
  if (!s.error.empty()) return s;
  s.end = header(kind, run_id).size();
  while (s.records.size() < max_records) {
    std::string record = r.getString();
    const auto crc = r.get<std::uint32_t>();
    if (!r.ok() || crc != crc32(record.data(), record.size())) break;  // end, or a torn last record
    s.end += 8 + record.size() + 4;
    s.records.push_back(std::move(record));
  }
  return s;
}

std::string readAll(const std::string& path, bool& exists) {
  std::ifstream in(path, std::ios::binary);
  exists = static_cast<bool>(in);
  return exists ? std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()) : std::string();
}

}  // namespace

LoadedRecords loadRecords(const std::string& path, const std::string& kind, const std::string& run_id,
                          std::size_t max_records) {
  LoadedRecords out;
  const std::string bytes = readAll(path, out.exists);
  if (!out.exists) return out;
  Scan s = scan(bytes, kind, run_id, max_records);
  out.error = s.error.empty() ? "" : path + ": " + s.error;
  out.records = std::move(s.records);
  return out;
}

RecordLog::~RecordLog() {
  if (file_) std::fclose(file_);
}

void RecordLog::create(const std::string& path, const std::string& kind, const std::string& run_id) {
  if (file_) std::fclose(file_);
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw std::runtime_error("cannot create " + path + ": " + std::strerror(errno));
  path_ = path;
  count_ = 0;
  const std::string h = header(kind, run_id);
  if (std::fwrite(h.data(), 1, h.size(), file_) != h.size() || std::fflush(file_) != 0)
    throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
}

void RecordLog::continueAfter(const std::string& path, std::size_t keep) {
  bool exists = false;
  const std::string bytes = readAll(path, exists);
  // The header was checked by loadRecords(); here only where the kept records end.
  ByteReader r(bytes);
  for (int i = 0; i < 8; ++i) r.get<char>();
  r.get<std::uint32_t>();
  const std::string kind = r.getString(), run_id = r.getString();
  const Scan s = scan(bytes, kind, run_id, keep);
  if (!exists || !s.error.empty() || s.records.size() != keep)
    throw std::runtime_error(path + ": fewer than " + std::to_string(keep) + " valid records");
  if (::truncate(path.c_str(), static_cast<off_t>(s.end)) != 0)
    throw std::runtime_error("cannot truncate " + path + ": " + std::strerror(errno));
  if (file_) std::fclose(file_);
  file_ = std::fopen(path.c_str(), "ab");
  if (!file_) throw std::runtime_error("cannot open " + path + ": " + std::strerror(errno));
  path_ = path;
  count_ = keep;
}

void RecordLog::append(const std::vector<std::string>& records) {
  if (!file_) throw std::runtime_error("record log not open");
  const long start = std::ftell(file_);
  ByteWriter w;
  for (const std::string& record : records) {
    w.putString(record);
    w.put<std::uint32_t>(crc32(record.data(), record.size()));
  }
  const bool written = std::fwrite(w.bytes().data(), 1, w.bytes().size(), file_) == w.bytes().size() &&
                       std::fflush(file_) == 0 && ::fdatasync(::fileno(file_)) == 0;
  if (!written) {
    const std::string reason = std::strerror(errno);
    // Cut off what part of the batch got out (a full disk): the records before stay valid and appendable.
    std::clearerr(file_);
    if (start >= 0 && ::ftruncate(::fileno(file_), start) == 0) std::fseek(file_, start, SEEK_SET);
    throw std::runtime_error("cannot append to " + path_ + ": " + reason);
  }
  count_ += records.size();
}

}  // namespace adit::runtime
