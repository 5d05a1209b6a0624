// Reading and writing LCM log files (the format of lcm-logger / lcm-logplayer) without the LCM library,
// so that a corrupt or truncated log is skipped over with a count instead of ending the run, and so that
// the bytes we write depend only on what we write (deterministic replay).
//
// Event framing (big-endian): sync 0xEDA1DA01, int64 event number, int64 timestamp (us), int32 channel
// length, int32 data length, channel bytes, data bytes.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace adit::runtime {

struct LogEvent {
  std::int64_t event_number = 0;
  std::int64_t timestamp = 0;  // microseconds
  std::string channel;
  std::vector<std::uint8_t> data;
};

class LogReader {
 public:
  // Throws std::runtime_error if the file cannot be opened.
  explicit LogReader(const std::string& path);
  ~LogReader();
  LogReader(const LogReader&) = delete;
  LogReader& operator=(const LogReader&) = delete;

  // Next well-formed event; false at end of file. Corrupt frames are skipped by resynchronising on the
  // next sync word; a truncated final frame ends the file. Both are counted.
  bool next(LogEvent& event);

  std::int64_t corruptFrames() const { return corrupt_frames_; }
  bool truncated() const { return truncated_; }
  // Fraction of the file consumed (for progress bars).
  double progress() const;

 private:
  bool resync();
  std::FILE* file_ = nullptr;
  std::int64_t size_ = 0;
  std::int64_t corrupt_frames_ = 0;
  bool truncated_ = false;
};

// Writes to "<path>.tmp.<pid>" and renames onto <path> on close(), so a reader never sees a half log.
// Every write is checked: on failure (disk full) the temp file is removed and std::runtime_error names
// the log. A writer destroyed without close() (an exception unwinding) removes its temp file: a log that
// is not complete never appears under its final name. A device or pipe (/dev/null, a FIFO) is written in
// place (io::writesInPlace): renaming over it would replace it with a regular file.
class LogWriter {
 public:
  // Throws std::runtime_error if the file cannot be created.
  explicit LogWriter(std::string path);
  ~LogWriter();  // discards the temp file if close() was not called
  LogWriter(const LogWriter&) = delete;
  LogWriter& operator=(const LogWriter&) = delete;

  void write(const std::string& channel, const std::uint8_t* data, std::size_t size, std::int64_t timestamp);
  void write(const std::string& channel, const std::vector<std::uint8_t>& data, std::int64_t timestamp) {
    write(channel, data.data(), data.size(), timestamp);
  }
  // Flush, fsync and rename into place. Throws std::runtime_error on I/O failure (temp file removed).
  void close();
  // Abandon the log: close and remove the temp file (no-op once closed).
  void discard();
  std::int64_t events() const { return next_event_; }
  const std::string& path() const { return path_; }

 private:
  [[noreturn]] void fail(const std::string& what);
  std::string path_;
  std::string tmp_path_;  // path_ itself when written in place
  bool in_place_ = false;
  std::FILE* file_ = nullptr;
  std::int64_t next_event_ = 0;
};

}  // namespace adit::runtime
