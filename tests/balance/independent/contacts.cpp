#include "independent/contacts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tonus::indep {

std::vector<double> rolling_percentile(std::span<const double> x, std::size_t half_window, double percentile) {
  std::vector<double> out(x.size(), std::numeric_limits<double>::quiet_NaN());
  std::vector<double> window;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const std::size_t lo = i > half_window ? i - half_window : 0;
    const std::size_t hi = std::min(x.size(), i + half_window + 1);
    window.clear();
    for (std::size_t k = lo; k < hi; ++k) {
      if (std::isfinite(x[k])) window.push_back(x[k]);
    }
    if (window.empty()) continue;
    const auto rank =
        static_cast<std::size_t>(std::clamp(percentile, 0.0, 1.0) * static_cast<double>(window.size() - 1));
    std::nth_element(window.begin(), window.begin() + static_cast<std::ptrdiff_t>(rank), window.end());
    out[i] = window[rank];
  }
  return out;
}

std::vector<bool> detect_contact(std::span<const double> height, std::span<const double> rest,
                                 std::span<const double> speed, const ContactOptions& o) {
  std::vector<bool> down(height.size(), false);
  bool on = false;
  for (std::size_t t = 0; t < height.size(); ++t) {
    const double above = height[t] - rest[t];
    // Comparisons with NaN are false: a point with no data is lifted.
    on = on ? (above < o.leave_height_m && speed[t] < o.leave_speed_mps)
            : (above < o.enter_height_m && speed[t] < o.enter_speed_mps);
    down[t] = on;
  }
  return down;
}

}  // namespace tonus::indep
