// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320: the CRC of zlib, PNG and MCAP), in one call or
// incrementally over pieces of a stream.
#pragma once

#include <cstddef>
#include <cstdint>

namespace adit {

class Crc32 {
 public:
  void update(const void* data, std::size_t size);
  std::uint32_t value() const { return state_ ^ 0xFFFFFFFFu; }

 private:
  std::uint32_t state_ = 0xFFFFFFFFu;
};

std::uint32_t crc32(const void* data, std::size_t size);

}  // namespace adit
