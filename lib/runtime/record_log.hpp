// An append-only file of checksummed records, for state that only grows (the loop closer's keyframes):
// appending costs the new records only, where rewriting a whole checkpoint would cost the whole run so far.
//
//   "ADITRLOG"  8 bytes magic, u32 version, string kind, string run id (u64 length + bytes)
//   records:    u64 length, bytes, u32 CRC-32 of the bytes
//
// A crash mid-append leaves a torn last record: it is detected by its length or checksum and cut off.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace adit::runtime {

struct LoadedRecords {
  bool exists = false;
  std::vector<std::string> records;  // the valid records, in order
  std::string error;                 // header refused (not a record log, other kind or run): records empty
};

// Reads at most max_records valid records. Never throws.
LoadedRecords loadRecords(const std::string& path, const std::string& kind, const std::string& run_id,
                          std::size_t max_records);

class RecordLog {
 public:
  RecordLog() = default;
  ~RecordLog();
  RecordLog(const RecordLog&) = delete;
  RecordLog& operator=(const RecordLog&) = delete;
  RecordLog(RecordLog&& other) noexcept { *this = std::move(other); }
  RecordLog& operator=(RecordLog&& other) noexcept {
    if (this != &other) {
      if (file_) std::fclose(file_);
      file_ = std::exchange(other.file_, nullptr);
      path_ = std::move(other.path_);
      count_ = std::exchange(other.count_, 0);
    }
    return *this;
  }

  // Starts a new file (any old one is replaced), or continues one whose first `keep` records are valid
  // (anything after them is cut off). Throws std::runtime_error naming the file.
  void create(const std::string& path, const std::string& kind, const std::string& run_id);
  void continueAfter(const std::string& path, std::size_t keep);
  // Appends and flushes to the disk (fdatasync). Throws std::runtime_error; the records before stay valid.
  void append(const std::vector<std::string>& records);
  std::size_t size() const { return count_; }
  bool isOpen() const { return file_ != nullptr; }

 private:
  std::FILE* file_ = nullptr;
  std::string path_;
  std::size_t count_ = 0;
};

}  // namespace adit::runtime
