#include "runtime/lcm_log.hpp"

#include "io/atomic_file.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace adit::runtime {
namespace {

constexpr std::uint32_t kSync = 0xEDA1DA01u;
constexpr std::int32_t kMaxChannelLength = 256;           // LCM itself allows 63
constexpr std::int64_t kMaxDataLength = 512LL << 20;      // far above any sane message
constexpr std::size_t kHeaderSize = 4 + 8 + 8 + 4 + 4;

std::uint64_t readBE(const std::uint8_t* p, int n) {
  std::uint64_t v = 0;
  for (int i = 0; i < n; ++i) v = (v << 8) | p[i];
  return v;
}

void writeBE(std::uint8_t* p, std::uint64_t v, int n) {
  for (int i = n - 1; i >= 0; --i) {
    p[i] = static_cast<std::uint8_t>(v & 0xFF);
    v >>= 8;
  }
}

}  // namespace

LogReader::LogReader(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw std::runtime_error("cannot open log '" + path + "': " + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw std::runtime_error("cannot read log '" + path + "': not a regular file");
  file_ = std::fopen(path.c_str(), "rb");
  if (!file_) throw std::runtime_error("cannot open log '" + path + "': " + std::strerror(errno));
  std::fseek(file_, 0, SEEK_END);
  size_ = std::ftell(file_);
  std::fseek(file_, 0, SEEK_SET);
}

LogReader::~LogReader() {
  if (file_) std::fclose(file_);
}

double LogReader::progress() const {
  if (!file_ || size_ <= 0) return 1.0;
  return static_cast<double>(std::ftell(file_)) / static_cast<double>(size_);
}

// Scan forward byte by byte until the next sync word; leaves the file positioned on it.
bool LogReader::resync() {
  std::uint32_t window = 0;
  int filled = 0;
  int c;
  while ((c = std::fgetc(file_)) != EOF) {
    window = (window << 8) | static_cast<std::uint32_t>(c);
    if (++filled >= 4 && window == kSync) {
      std::fseek(file_, -4, SEEK_CUR);
      return true;
    }
  }
  return false;
}

bool LogReader::next(LogEvent& event) {
  while (true) {
    const long start = std::ftell(file_);
    std::array<std::uint8_t, kHeaderSize> header{};
    const std::size_t got = std::fread(header.data(), 1, header.size(), file_);
    if (got == 0) return false;
    if (got < header.size()) {
      truncated_ = true;
      return false;
    }
    const auto sync = static_cast<std::uint32_t>(readBE(header.data(), 4));
    const auto channel_len = static_cast<std::int32_t>(readBE(header.data() + 20, 4));
    const auto data_len = static_cast<std::int32_t>(readBE(header.data() + 24, 4));
    const bool plausible = sync == kSync && channel_len > 0 && channel_len <= kMaxChannelLength && data_len >= 0 &&
                           data_len <= kMaxDataLength;
    const bool fits = start + static_cast<long>(kHeaderSize) + channel_len + data_len <= size_;
    if (!plausible || !fits) {
      std::fseek(file_, start + 1, SEEK_SET);
      if (!resync()) {
        // Nothing follows: a plausible frame cut short is a truncated tail, anything else is corrupt.
        if (plausible) truncated_ = true; else ++corrupt_frames_;
        return false;
      }
      ++corrupt_frames_;
      continue;
    }
    event.event_number = static_cast<std::int64_t>(readBE(header.data() + 4, 8));
    event.timestamp = static_cast<std::int64_t>(readBE(header.data() + 12, 8));
    event.channel.resize(static_cast<std::size_t>(channel_len));
    event.data.resize(static_cast<std::size_t>(data_len));
    if (std::fread(event.channel.data(), 1, event.channel.size(), file_) != event.channel.size() ||
        std::fread(event.data.data(), 1, event.data.size(), file_) != event.data.size()) {
      truncated_ = true;
      return false;
    }
    // Channel names are printable; anything else means we synced on a sync word inside a payload.
    bool printable = true;
    for (char ch : event.channel) printable = printable && ch > 32 && ch < 127;
    if (!printable) {
      ++corrupt_frames_;
      std::fseek(file_, start + 1, SEEK_SET);
      if (!resync()) return false;
      continue;
    }
    return true;
  }
}

LogWriter::LogWriter(std::string path) : path_(std::move(path)) {
  in_place_ = io::writesInPlace(path_);  // a device or pipe (/dev/null, a FIFO): never renamed over
  tmp_path_ = in_place_ ? path_ : io::atomicTempPath(path_);
  file_ = std::fopen(tmp_path_.c_str(), "wb");
  if (!file_) throw std::runtime_error("cannot create log '" + tmp_path_ + "': " + std::strerror(errno));
}

LogWriter::~LogWriter() { discard(); }

void LogWriter::discard() {
  if (!file_) return;
  std::fclose(file_);
  file_ = nullptr;
  if (!in_place_) std::remove(tmp_path_.c_str());
}

void LogWriter::fail(const std::string& what) {
  const std::string reason = errno ? std::strerror(errno) : "unknown error";
  discard();
  throw std::runtime_error("cannot write log '" + path_ + "': " + what + ": " + reason + " (nothing written)");
}

void LogWriter::write(const std::string& channel, const std::uint8_t* data, std::size_t size, std::int64_t timestamp) {
  if (!file_) throw std::runtime_error("log '" + path_ + "' is closed");
  if (channel.empty() || channel.size() > static_cast<std::size_t>(kMaxChannelLength) ||
      size > static_cast<std::size_t>(kMaxDataLength))
    throw std::runtime_error("log '" + path_ + "': event on '" + channel.substr(0, 64) + "' of " + std::to_string(size) +
                             " bytes cannot be framed");
  std::array<std::uint8_t, kHeaderSize> header{};
  writeBE(header.data(), kSync, 4);
  writeBE(header.data() + 4, static_cast<std::uint64_t>(next_event_++), 8);
  writeBE(header.data() + 12, static_cast<std::uint64_t>(timestamp), 8);
  writeBE(header.data() + 20, channel.size(), 4);
  writeBE(header.data() + 24, size, 4);
  errno = 0;
  if (std::fwrite(header.data(), 1, header.size(), file_) != header.size() ||
      std::fwrite(channel.data(), 1, channel.size(), file_) != channel.size() ||
      (size && std::fwrite(data, 1, size, file_) != size))
    fail("write failed (disk full?)");
}

void LogWriter::close() {
  if (!file_) return;
  errno = 0;
  if (std::fflush(file_) != 0 || (!in_place_ && ::fsync(::fileno(file_)) != 0)) fail("flush failed (disk full?)");
  std::FILE* file = file_;
  file_ = nullptr;
  if (std::fclose(file) != 0) {
    if (!in_place_) std::remove(tmp_path_.c_str());
    throw std::runtime_error("cannot write log '" + path_ + "': close failed: " + std::strerror(errno) + " (nothing written)");
  }
  if (in_place_) return;
  if (std::rename(tmp_path_.c_str(), path_.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(tmp_path_.c_str());
    throw std::runtime_error("cannot rename '" + tmp_path_ + "' to '" + path_ + "': " + reason);
  }
}

}  // namespace adit::runtime
