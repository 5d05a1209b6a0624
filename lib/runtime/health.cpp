#include "runtime/health.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace adit::runtime {

void TimingWindow::add(double ms) {
  samples_.push_back(ms);
  while (capacity_ > 0 && samples_.size() > capacity_) samples_.pop_front();
}

double TimingWindow::quantile(double q) const {
  if (samples_.empty()) return 0.0;
  std::vector<double> sorted(samples_.begin(), samples_.end());
  std::sort(sorted.begin(), sorted.end());
  const auto index = static_cast<std::size_t>(std::lround(q * static_cast<double>(sorted.size() - 1)));
  return sorted[std::min(index, sorted.size() - 1)];
}

double TimingWindow::max() const {
  return samples_.empty() ? 0.0 : *std::max_element(samples_.begin(), samples_.end());
}

}  // namespace adit::runtime
