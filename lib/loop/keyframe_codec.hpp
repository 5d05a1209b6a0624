// A keyframe's cloud and Scan Context as bytes: shared by the loop closer's checkpoint records and the map
// bundle's keyframe file, so both read and validate them the same way.
#pragma once

#include "core/byte_codec.hpp"
#include "loop/compact_cloud.hpp"
#include "loop/scan_context.hpp"

#include <optional>

namespace adit {

void putCompactCloud(ByteWriter& w, const CompactCloud& cloud);
// nullopt (and the reader failed) on a malformed cloud.
std::optional<CompactCloud> getCompactCloud(ByteReader& r);

void putScanContext(ByteWriter& w, const ScanContext& context);
// nullopt (and the reader failed) on implausible sizes or too few bytes left.
std::optional<ScanContext> getScanContext(ByteReader& r);

}  // namespace adit
