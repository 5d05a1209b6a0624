// Compacting per-keyframe containers when keyframes are merged out of the graph: keep[k] says which stay.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace adit {

// Items whose keep[k] is false are removed, the others keep their order (indices past keep.size() stay).
// Never moves an item onto itself: a self-moved std::vector is left empty by libstdc++.
template <class T>
void eraseUnkept(std::vector<T>& items, const std::vector<bool>& keep) {
  std::size_t out = 0;
  for (std::size_t k = 0; k < items.size(); ++k) {
    if (k < keep.size() && !keep[k]) continue;
    if (out != k) items[out] = std::move(items[k]);
    ++out;
  }
  items.resize(out);
}

// How many of the first n items stay.
inline std::size_t keptAmongFirst(const std::vector<bool>& keep, std::size_t n) {
  std::size_t kept = 0;
  for (std::size_t k = 0; k < n; ++k) kept += k < keep.size() && !keep[k] ? 0 : 1;
  return kept;
}

}  // namespace adit
