// LZF decompression (the codec of PCD's binary_compressed body), checked at every step: a corrupt or
// hostile input gives false, never a read or write outside the buffers.
#pragma once

#include <cstddef>
#include <cstdint>

namespace adit::io {

// Decompresses `in` into exactly `out_size` bytes at `out`. False if the stream is corrupt, refers
// before the start of the output, or does not produce exactly out_size bytes.
bool lzfDecompress(const std::uint8_t* in, std::size_t in_size, std::uint8_t* out, std::size_t out_size);

// The most bytes an LZF stream of `in_size` bytes can expand to: a 3-byte back reference copies at most
// 264 bytes. Bounds what a header may make us allocate.
constexpr std::size_t lzfMaxExpansion(std::size_t in_size) { return in_size / 3 * 264 + 264; }

}  // namespace adit::io
