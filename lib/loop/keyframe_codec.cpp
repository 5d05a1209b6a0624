#include "loop/keyframe_codec.hpp"

namespace adit {

void putCompactCloud(ByteWriter& w, const CompactCloud& cloud) {
  w.put<float>(cloud.step());
  w.put<std::uint64_t>(cloud.counts().size());
  for (std::int16_t c : cloud.counts()) w.put<std::int16_t>(c);
}

std::optional<CompactCloud> getCompactCloud(ByteReader& r) {
  const float step = r.get<float>();
  std::vector<std::int16_t> counts(r.getCount(sizeof(std::int16_t)));
  for (std::int16_t& c : counts) c = r.get<std::int16_t>();
  std::optional<CompactCloud> cloud = CompactCloud::fromCounts(step, std::move(counts));
  if (!r.ok() || !cloud) {
    r.fail();
    return std::nullopt;
  }
  return cloud;
}

void putScanContext(ByteWriter& w, const ScanContext& sc) {
  w.put<std::int32_t>(sc.rings());
  w.put<std::int32_t>(sc.sectors());
  w.put<std::int32_t>(sc.shiftSearchRadius());
  w.putMatrix(sc.descriptor());
}

std::optional<ScanContext> getScanContext(ByteReader& r) {
  const int rings = r.get<std::int32_t>(), sectors = r.get<std::int32_t>(), radius = r.get<std::int32_t>();
  if (r.ok() && rings == 0 && sectors == 0 && radius >= 0) return ScanContext();  // a keyframe with no place context
  // Sizes are checked against the bytes left before anything is allocated.
  if (!r.ok() || rings <= 0 || sectors <= 0 || rings > 1000 || sectors > 1000 || radius < 0 ||
      static_cast<std::uint64_t>(rings) * static_cast<std::uint64_t>(sectors) * 4 > r.left()) {
    r.fail();
    return std::nullopt;
  }
  Eigen::MatrixXf descriptor(rings, sectors);
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < sectors; ++j) descriptor(i, j) = r.get<float>();
  if (!r.ok() || !descriptor.allFinite()) {
    r.fail();
    return std::nullopt;
  }
  return ScanContext::fromDescriptor(descriptor, radius);
}

}  // namespace adit
