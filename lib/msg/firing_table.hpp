// A spinning head's firing table, as the compact sweep encoder (msg/sweep_codec.hpp) needs it: for each ring
// (0 = lowest), the time of its firing after the first firing of its column (one firing sequence of all
// beams). Built by the drivers from their packet timing (drivers/firing.hpp) and by the simulator source from
// its lidar profile. Plain data: no LCM.
#pragma once

#include <cstdint>
#include <vector>

namespace adit::msg {

struct FiringTable {
  std::vector<std::int32_t> ring_offset_ns;  // per ring, >= 0
  int beams() const { return static_cast<int>(ring_offset_ns.size()); }
};

}  // namespace adit::msg
