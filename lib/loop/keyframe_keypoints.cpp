#include "loop/keyframe_keypoints.hpp"

#include <algorithm>
#include <cmath>

namespace adit {
namespace {
constexpr float kCm = 0.01f;  // 5 mm rounding against a bin tolerance of decimetres
constexpr std::size_t kMinKeypointBytes = 3 * sizeof(float) + 1;
constexpr std::size_t kEntryBytes = 1 + sizeof(std::uint16_t);
}  // namespace

KeyframeKeypoints KeyframeKeypoints::encode(const std::vector<Eigen::Vector3f>& keypoints,
                                            const std::vector<LinK3dDescriptor>& descriptors) {
  KeyframeKeypoints out;
  const std::size_t n = std::min(keypoints.size(), descriptors.size());
  for (std::size_t i = 0; i < n; ++i) {
    if (!keypoints[i].allFinite()) continue;
    out.points_.push_back(keypoints[i]);
    for (int b = 0; b < kLinK3dBins; ++b) {
      const float cm = descriptors[i][static_cast<std::size_t>(b)] / kCm;
      if (!(cm >= 0.5f)) continue;  // empty, NaN, or closer than 5 mm: nothing a match could use
      out.bin_.push_back(static_cast<std::uint8_t>(b));
      out.dist_.push_back(cm >= 65535.0f ? std::uint16_t{65535} : static_cast<std::uint16_t>(std::lround(cm)));
    }
    out.end_.push_back(static_cast<std::uint32_t>(out.bin_.size()));
  }
  return out;
}

std::vector<LinK3dDescriptor> KeyframeKeypoints::descriptors() const {
  std::vector<LinK3dDescriptor> out(points_.size());
  std::size_t e = 0;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    out[i].fill(0.0f);
    for (; e < end_[i]; ++e) out[i][bin_[e]] = static_cast<float>(dist_[e]) * kCm;
  }
  return out;
}

std::size_t KeyframeKeypoints::bytes() const {
  return points_.capacity() * sizeof(Eigen::Vector3f) + end_.capacity() * sizeof(std::uint32_t) +
         bin_.capacity() + dist_.capacity() * sizeof(std::uint16_t);
}

void KeyframeKeypoints::put(ByteWriter& w) const {
  w.put<std::uint64_t>(points_.size());
  std::size_t e = 0;
  for (std::size_t i = 0; i < points_.size(); ++i) {
    for (int k = 0; k < 3; ++k) w.put<float>(points_[i][k]);
    w.put<std::uint8_t>(static_cast<std::uint8_t>(end_[i] - e));
    for (; e < end_[i]; ++e) {
      w.put<std::uint8_t>(bin_[e]);
      w.put<std::uint16_t>(dist_[e]);
    }
  }
}

std::optional<KeyframeKeypoints> KeyframeKeypoints::get(ByteReader& r) {
  KeyframeKeypoints out;
  const std::uint64_t n = r.getCount(kMinKeypointBytes);
  for (std::uint64_t i = 0; i < n && r.ok(); ++i) {
    Eigen::Vector3f p;
    for (int k = 0; k < 3; ++k) p[k] = r.get<float>();
    const int entries = r.get<std::uint8_t>();
    if (!p.allFinite() || entries > kLinK3dBins || r.left() < static_cast<std::size_t>(entries) * kEntryBytes) r.fail();
    for (int e = 0; e < entries && r.ok(); ++e) {
      const std::uint8_t bin = r.get<std::uint8_t>();
      const std::uint16_t dist = r.get<std::uint16_t>();
      // Bins of one keypoint ascend (as encode() writes them), each below kLinK3dBins.
      const bool ascending = e == 0 || bin > out.bin_.back();
      if (bin >= kLinK3dBins || !ascending || dist == 0) r.fail();
      out.bin_.push_back(bin);
      out.dist_.push_back(dist);
    }
    out.points_.push_back(p);
    out.end_.push_back(static_cast<std::uint32_t>(out.bin_.size()));
  }
  if (!r.ok()) return std::nullopt;
  return out;
}

}  // namespace adit
