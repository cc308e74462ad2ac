// Maps the band's clock to the host's steady clock from time_sync exchanges
// (docs/protocol.md 3.3): offset and drift, robust to round-trip spread.
//
// Each exchange bounds the offset (device minus host): t3 - t4 <= offset <=
// t2 - t1, each bound tight when its one-way delay is small. The delays are
// mostly waiting (the band answers on its next poll, its response leaves on the
// next USB frame; over a Unix socket: min 58 us, median 1 ms), so, as NTP's
// clock filter and PTP-style lower-envelope fits do, only the tightest bound of
// each kind in each group of `group` consecutive exchanges is kept; a line is
// fitted through each envelope (least squares, then again without the points
// beyond 3 robust sigmas) and the offset runs midway between them. Drift is
// fitted once the exchanges span `min_span_us`.
//
// A host whose requests follow the band's stream (sent just after a report
// arrives) meets the band at the same phase of its cycle every time, and every
// exchange then has the same asymmetry: exchange_time_sync waits a random
// fraction of `dither` first, so that some exchanges catch the band just
// before its poll.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>

#include "tonus/host/transport/band_link.hpp"

namespace tonus::host {

struct TimeSyncSample {
  std::int64_t t1_host_us = 0;     // request sent (host steady clock)
  std::uint64_t t2_device_us = 0;  // request received (device clock)
  std::uint64_t t3_device_us = 0;  // response sent (device clock)
  std::int64_t t4_host_us = 0;     // response received (host steady clock)

  [[nodiscard]] double round_trip_us() const;
  [[nodiscard]] double offset_us() const;  // device minus host, NTP's estimate
  [[nodiscard]] double host_mid_us() const {
    return static_cast<double>(t1_host_us) + 0.5 * static_cast<double>(t4_host_us - t1_host_us);
  }
};

class ClockSync {
 public:
  struct Options {
    std::size_t window = 512;        // exchanges kept (the oldest go first)
    std::size_t group = 16;          // the tightest bounds of each group of exchanges are kept
    double min_span_us = 1e6;        // exchanges must span this long before drift is fitted
    double max_round_trip_us = 1e6;  // longer exchanges say nothing useful: refused
  };

  ClockSync() : ClockSync(Options{}) {}
  explicit ClockSync(Options o) : opt_(o) {}

  // False (and counted) for an inconsistent or useless exchange.
  bool add(const TimeSyncSample& s);

  [[nodiscard]] bool ready() const { return fitted_; }
  [[nodiscard]] double offset_us_at(double host_us) const { return offset_us_ + drift_ * (host_us - ref_host_us_); }
  [[nodiscard]] double drift_ppm() const { return drift_ * 1e6; }
  [[nodiscard]] double host_from_device_us(double device_us) const;
  [[nodiscard]] double device_from_host_us(double host_us) const { return host_us + offset_us_at(host_us); }
  // The stream's 32-bit device_time_us extended to the 64-bit device clock,
  // nearest to the latest exchange (valid within +-35 min of it).
  [[nodiscard]] std::uint64_t extend(std::uint32_t device_time_us) const;

  [[nodiscard]] std::size_t samples() const { return samples_.size(); }
  [[nodiscard]] std::uint64_t rejected() const { return rejected_; }
  [[nodiscard]] double min_round_trip_us() const { return min_rtt_us_; }

 private:
  void refit();

  Options opt_;
  std::deque<TimeSyncSample> samples_;
  bool fitted_ = false;
  double ref_host_us_ = 0.0;
  double offset_us_ = 0.0;  // device minus host at ref_host_us_
  double drift_ = 0.0;      // d(offset)/d(host time), dimensionless
  std::uint64_t last_device_us_ = 0;
  std::uint64_t rejected_ = 0;
  double min_rtt_us_ = 0.0;
};

// One time_sync exchange over `link` (stream reports meanwhile go to `sink`),
// sent after a random wait of up to `dither` (one band poll / USB frame).
std::optional<TimeSyncSample> exchange_time_sync(BandLink& link, std::uint8_t token, int timeout_ms,
                                                 const BandLink::StreamSink& sink = {},
                                                 std::chrono::microseconds dither = std::chrono::microseconds(1000));

}  // namespace tonus::host
