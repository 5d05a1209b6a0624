#include "io/lzf.hpp"

namespace adit::io {

// Format (liblzf): a control byte c < 32 is a literal run of c + 1 bytes; otherwise the top three bits are
// the match length - 2 (7 = one more length byte follows), the low five bits and the next byte the
// distance - 1 back into the output.
bool lzfDecompress(const std::uint8_t* in, std::size_t in_size, std::uint8_t* out, std::size_t out_size) {
  std::size_t ip = 0, op = 0;
  while (ip < in_size) {
    const unsigned ctrl = in[ip++];
    if (ctrl < 32) {
      const std::size_t len = ctrl + 1;
      if (len > in_size - ip || len > out_size - op) return false;
      for (std::size_t k = 0; k < len; ++k) out[op++] = in[ip++];
      continue;
    }
    std::size_t len = ctrl >> 5;
    if (len == 7) {
      if (ip >= in_size) return false;
      len += in[ip++];
    }
    if (ip >= in_size) return false;
    const std::size_t distance = ((ctrl & 0x1Fu) << 8) + in[ip++] + 1;
    len += 2;
    if (distance > op || len > out_size - op) return false;
    for (std::size_t k = 0; k < len; ++k, ++op) out[op] = out[op - distance];  // may overlap: byte by byte
  }
  return op == out_size;
}

}  // namespace adit::io
