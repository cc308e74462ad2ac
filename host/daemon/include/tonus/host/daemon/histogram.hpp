// Durations counted into fixed bins, so a real-time thread can record every
// tick's cost without allocating, and p50 / p99 / max come out exact to one
// bin. Values beyond the last bin are counted in an overflow bin (and still
// set the max), so a tail is never lost.
#pragma once

#include <cstdint>
#include <vector>

namespace tonus::daemon {

class Histogram {
 public:
  // Bins of `bin_us` microseconds from 0 to bin_us * bins; allocated here, once.
  Histogram(double bin_us, std::size_t bins);

  void add(double value_us);  // never allocates; non-finite or negative values count as 0
  void clear();

  [[nodiscard]] std::uint64_t count() const { return count_; }
  [[nodiscard]] double max_us() const { return max_us_; }
  [[nodiscard]] double mean_us() const { return count_ > 0 ? sum_us_ / static_cast<double>(count_) : 0.0; }
  // The upper edge of the bin holding the q-quantile (q in 0..1); the max for
  // a quantile in the overflow bin; 0 when empty.
  [[nodiscard]] double quantile_us(double q) const;
  [[nodiscard]] std::uint64_t overflow() const { return bins_.back(); }
  // Values above `threshold_us`, counted to the bin (for overrun shares).
  [[nodiscard]] std::uint64_t count_above(double threshold_us) const;
  // Adds another histogram with the same bins.
  void merge(const Histogram& other);

 private:
  double bin_us_;
  std::vector<std::uint64_t> bins_;  // the last one is the overflow
  std::uint64_t count_ = 0;
  double sum_us_ = 0.0;
  double max_us_ = 0.0;
};

}  // namespace tonus::daemon
