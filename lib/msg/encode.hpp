// Encoding an LCM message into a byte buffer (what the bus, the logs and the sources carry).
#pragma once

#include <cstdint>
#include <vector>

namespace adit::msg {

template <class Msg>
std::vector<std::uint8_t> encode(const Msg& m) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

}  // namespace adit::msg
