#include "loop/keyframe_cloud_store.hpp"

#include "loop/keep_mask.hpp"

#include <utility>

namespace adit {

std::size_t KeyframeCloudStore::bytesOf(const Slot& slot) {
  return slot.cloud.bytes() + (slot.keypoints ? slot.keypoints->bytes() : 0);
}

void KeyframeCloudStore::add(CompactCloud cloud, KeyframeKeypointsPtr keypoints) {
  Slot slot;
  slot.points = static_cast<std::uint32_t>(cloud.size());
  slot.step = cloud.step();
  slot.cloud = std::move(cloud);
  if (keypoints && !keypoints->empty()) slot.keypoints = std::move(keypoints);
  resident_bytes_ += bytesOf(slot);
  slots_.push_back(std::move(slot));
  pageOut();
}

void KeyframeCloudStore::drop(int k) {
  Slot& slot = slots_.at(static_cast<std::size_t>(k));
  resident_bytes_ -= bytesOf(slot);
  const float step = slot.step;
  slot = Slot{};
  slot.cloud = CompactCloud::encode({}, step > 0 ? step : 1e-3f);
  slot.step = step;
}

void KeyframeCloudStore::retain(const std::vector<bool>& keep) {
  for (std::size_t k = 0; k < slots_.size() && k < keep.size(); ++k)
    if (!keep[k]) resident_bytes_ -= bytesOf(slots_[k]);
  queue_.retain(keep);
  eraseUnkept(slots_, keep);
  slots_.shrink_to_fit();
}

bool KeyframeCloudStore::empty(int k) const { return slots_.at(static_cast<std::size_t>(k)).points == 0; }

CompactCloud KeyframeCloudStore::cloud(int k) const {
  const Slot& slot = slots_.at(static_cast<std::size_t>(k));
  if (slot.offset < 0) return slot.cloud;
  std::vector<std::int16_t> counts(static_cast<std::size_t>(slot.points) * 3);
  std::optional<CompactCloud> read;
  if (file_.read(slot.offset, counts.data(), counts.size() * sizeof(std::int16_t)))
    read = CompactCloud::fromCounts(slot.step, std::move(counts));
  if (!read) {
    ++read_errors_;
    return CompactCloud::encode({}, slot.step);
  }
  return std::move(*read);
}

KeyframeKeypointsPtr KeyframeCloudStore::keypoints(int k) const {
  const Slot& slot = slots_.at(static_cast<std::size_t>(k));
  if (slot.offset < 0 || slot.keypoint_bytes == 0) return slot.keypoints;
  std::string bytes(slot.keypoint_bytes, '\0');
  const std::int64_t at = slot.offset + static_cast<std::int64_t>(slot.points) * 3 * sizeof(std::int16_t);
  if (file_.read(at, bytes.data(), bytes.size())) {
    ByteReader r(bytes);
    if (std::optional<KeyframeKeypoints> read = KeyframeKeypoints::get(r); read && r.ok() && r.atEnd())
      return std::make_shared<const KeyframeKeypoints>(std::move(*read));
  }
  ++read_errors_;
  return nullptr;
}

void KeyframeCloudStore::pageTo(const std::string& path, std::size_t resident) {
  PageFile file = PageFile::create(path, "keyframe cloud");
  // Keyframes paged to an earlier file come back into memory first, then go to the new one.
  for (std::size_t k = 0; k < slots_.size(); ++k) {
    Slot& slot = slots_[k];
    if (slot.offset < 0) continue;
    slot.cloud = cloud(static_cast<int>(k));
    slot.keypoints = keypoints(static_cast<int>(k));
    slot.offset = -1;
    slot.keypoint_bytes = 0;
    resident_bytes_ += bytesOf(slot);
  }
  file_ = std::move(file);
  queue_.restart(resident);
  pageOut();
}

void KeyframeCloudStore::pageOut() {
  if (file_.isOpen()) queue_.pageOut(slots_.size(), [this](std::size_t k) { return pageOne(slots_[k]); });
}

// One record: the cloud's counts, then its keypoints.
PagingQueue::Outcome KeyframeCloudStore::pageOne(Slot& slot) {
  if (slot.points == 0 || slot.offset >= 0) return PagingQueue::Outcome::kNothingToPage;
  const std::vector<std::int16_t>& counts = slot.cloud.counts();
  ByteWriter keypoints;
  if (slot.keypoints) slot.keypoints->put(keypoints);
  std::string record(reinterpret_cast<const char*>(counts.data()), counts.size() * sizeof(std::int16_t));
  record += keypoints.bytes();
  const std::int64_t offset = file_.append(record.data(), record.size());
  if (offset < 0) return PagingQueue::Outcome::kFailed;  // kept in memory; the next add tries again
  resident_bytes_ -= bytesOf(slot);
  slot.offset = offset;
  slot.keypoint_bytes = static_cast<std::uint32_t>(keypoints.bytes().size());
  slot.cloud = CompactCloud();
  slot.keypoints.reset();
  return PagingQueue::Outcome::kPaged;
}

std::size_t KeyframeCloudStore::residentBytes() const { return slots_.capacity() * sizeof(Slot) + resident_bytes_; }

}  // namespace adit
