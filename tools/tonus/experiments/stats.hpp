// Small statistics the experiments report: a percentile by selection.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace tonus::experiments {

// The value at fraction p (0..1) of the sorted samples (nearest rank below); 0 for none.
inline double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::clamp(p, 0.0, 1.0) * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace tonus::experiments
