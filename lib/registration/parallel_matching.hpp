// Correspondence search over a ChunkPool: line queries [0, num_lines) and plane queries [0, num_planes) as
// one index range cut into fixed chunks, each chunk's matches kept apart and joined in query order. The
// result is the one a single loop over the lines then the planes gives, bit for bit.
#pragma once

#include "core/chunk_pool.hpp"
#include "registration/correspondences.hpp"

#include <algorithm>
#include <vector>

namespace adit {

// add_line(i, lines) / add_plane(i, planes): append query i's match, if it has one. Both are called from
// several threads at once: they may only read shared state. pool == nullptr: one thread.
template <class AddLine, class AddPlane>
Correspondences matchInChunks(ChunkPool* pool, std::size_t num_lines, std::size_t num_planes,
                              const AddLine& add_line, const AddPlane& add_plane) {
  // Several chunks per thread (of at least 32 queries): a thread that is late or slow holds up little.
  const std::size_t n = num_lines + num_planes;
  const int chunks = pool && pool->threads() > 1
                         ? static_cast<int>(std::max<std::size_t>(1, std::min<std::size_t>(8 * pool->threads(), n / 32)))
                         : 1;
  std::vector<Correspondences> parts(static_cast<std::size_t>(chunks));
  const auto search = [&](int chunk, std::size_t begin, std::size_t end) {
    Correspondences& part = parts[static_cast<std::size_t>(chunk)];
    for (std::size_t i = begin; i < end; ++i) {
      if (i < num_lines) add_line(i, part.lines);
      else add_plane(i - num_lines, part.planes);
    }
  };
  if (chunks > 1) pool->run(n, chunks, search);
  else search(0, 0, n);
  if (chunks == 1) return std::move(parts.front());
  Correspondences all;
  std::size_t lines = 0, planes = 0;
  for (const Correspondences& p : parts) lines += p.lines.size(), planes += p.planes.size();
  all.lines.reserve(lines);
  all.planes.reserve(planes);
  for (const Correspondences& p : parts) {
    all.lines.insert(all.lines.end(), p.lines.begin(), p.lines.end());
    all.planes.insert(all.planes.end(), p.planes.begin(), p.planes.end());
  }
  return all;
}

}  // namespace adit
