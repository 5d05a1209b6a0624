#include "core/base64.hpp"

#include <cstdint>

namespace adit {

std::string base64(const std::string& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve(4 * ((bytes.size() + 2) / 3));
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const std::uint32_t v = static_cast<std::uint32_t>(static_cast<std::uint8_t>(bytes[i])) << 16 |
                            static_cast<std::uint32_t>(static_cast<std::uint8_t>(bytes[i + 1])) << 8 |
                            static_cast<std::uint8_t>(bytes[i + 2]);
    for (int k = 3; k >= 0; --k) out += kAlphabet[(v >> (6 * k)) & 63u];
  }
  if (i < bytes.size()) {  // one or two bytes left: pad to four characters
    const bool two = i + 1 < bytes.size();
    const std::uint32_t v = static_cast<std::uint32_t>(static_cast<std::uint8_t>(bytes[i])) << 16 |
                            (two ? static_cast<std::uint32_t>(static_cast<std::uint8_t>(bytes[i + 1])) << 8 : 0u);
    out += kAlphabet[(v >> 18) & 63u];
    out += kAlphabet[(v >> 12) & 63u];
    out += two ? kAlphabet[(v >> 6) & 63u] : '=';
    out += '=';
  }
  return out;
}

}  // namespace adit
