#include "loop/keyframe_cloud_store.hpp"

#include "loop/keep_mask.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace adit {
namespace {

// pwrite or pread of the whole buffer (both may transfer less than asked); false on an error or end of file.
template <class Buffer, class Transfer>
bool transferAll(Transfer transfer, int fd, Buffer* data, std::size_t bytes, std::int64_t offset) {
  while (bytes > 0) {
    const ssize_t n = transfer(fd, data, bytes, static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    data += n;
    bytes -= static_cast<std::size_t>(n);
    offset += n;
  }
  return true;
}

bool writeAll(int fd, const void* data, std::size_t bytes, std::int64_t offset) {
  return transferAll(::pwrite, fd, static_cast<const char*>(data), bytes, offset);
}

bool readAll(int fd, void* data, std::size_t bytes, std::int64_t offset) {
  return transferAll(::pread, fd, static_cast<char*>(data), bytes, offset);
}

}  // namespace

KeyframeCloudStore::~KeyframeCloudStore() { close(); }

KeyframeCloudStore::KeyframeCloudStore(KeyframeCloudStore&& other) noexcept { *this = std::move(other); }

KeyframeCloudStore& KeyframeCloudStore::operator=(KeyframeCloudStore&& other) noexcept {
  if (this == &other) return *this;
  close();
  slots_ = std::move(other.slots_);
  fd_ = std::exchange(other.fd_, -1);
  end_ = std::exchange(other.end_, 0);
  resident_ = other.resident_;
  resident_bytes_ = std::exchange(other.resident_bytes_, 0);
  next_to_page_ = std::exchange(other.next_to_page_, 0);
  paged_ = std::exchange(other.paged_, 0);
  page_errors_ = std::exchange(other.page_errors_, 0);
  read_errors_ = std::exchange(other.read_errors_, 0);
  return *this;
}

void KeyframeCloudStore::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void KeyframeCloudStore::add(CompactCloud cloud) {
  Slot slot;
  slot.points = static_cast<std::uint32_t>(cloud.size());
  slot.step = cloud.step();
  slot.cloud = std::move(cloud);
  resident_bytes_ += slot.cloud.bytes();
  slots_.push_back(std::move(slot));
  pageOut();
}

void KeyframeCloudStore::drop(int k) {
  Slot& slot = slots_.at(static_cast<std::size_t>(k));
  resident_bytes_ -= slot.cloud.bytes();
  slot = Slot{CompactCloud::encode({}, slot.step > 0 ? slot.step : 1e-3f), -1, 0, slot.step};
}

void KeyframeCloudStore::retain(const std::vector<bool>& keep) {
  for (std::size_t k = 0; k < slots_.size() && k < keep.size(); ++k)
    if (!keep[k]) resident_bytes_ -= slots_[k].cloud.bytes();
  next_to_page_ = keptAmongFirst(keep, next_to_page_);
  eraseUnkept(slots_, keep);
  slots_.shrink_to_fit();
}

bool KeyframeCloudStore::empty(int k) const { return slots_.at(static_cast<std::size_t>(k)).points == 0; }

CompactCloud KeyframeCloudStore::cloud(int k) const {
  const Slot& slot = slots_.at(static_cast<std::size_t>(k));
  if (slot.offset < 0) return slot.cloud;
  std::vector<std::int16_t> counts(static_cast<std::size_t>(slot.points) * 3);
  std::optional<CompactCloud> read;
  if (readAll(fd_, counts.data(), counts.size() * sizeof(std::int16_t), slot.offset))
    read = CompactCloud::fromCounts(slot.step, std::move(counts));
  if (!read) {
    ++read_errors_;
    return CompactCloud::encode({}, slot.step);
  }
  return std::move(*read);
}

void KeyframeCloudStore::pageTo(const std::string& path, std::size_t resident) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) throw std::runtime_error("cannot create the cloud page file " + path + ": " + std::strerror(errno));
  ::unlink(path.c_str());
  // Clouds paged to an earlier file come back into memory first, then go to the new one.
  for (std::size_t k = 0; k < slots_.size(); ++k) {
    if (slots_[k].offset < 0) continue;
    slots_[k].cloud = cloud(static_cast<int>(k));
    slots_[k].offset = -1;
    resident_bytes_ += slots_[k].cloud.bytes();
  }
  close();
  fd_ = fd;
  end_ = 0;
  resident_ = resident;
  next_to_page_ = 0;
  paged_ = 0;
  pageOut();
}

void KeyframeCloudStore::pageOut() {
  if (fd_ < 0) return;
  while (slots_.size() - next_to_page_ > resident_) {
    Slot& slot = slots_[next_to_page_];
    if (slot.points > 0 && slot.offset < 0) {
      const std::vector<std::int16_t>& counts = slot.cloud.counts();
      if (!writeAll(fd_, counts.data(), counts.size() * sizeof(std::int16_t), end_)) {
        ++page_errors_;  // kept in memory; the next add tries again
        return;
      }
      slot.offset = end_;
      end_ += static_cast<std::int64_t>(counts.size() * sizeof(std::int16_t));
      resident_bytes_ -= slot.cloud.bytes();
      slot.cloud = CompactCloud();
      ++paged_;
    }
    ++next_to_page_;
  }
}

std::size_t KeyframeCloudStore::residentBytes() const { return slots_.capacity() * sizeof(Slot) + resident_bytes_; }

}  // namespace adit
