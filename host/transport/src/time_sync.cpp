#include "tonus/host/transport/time_sync.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <thread>
#include <vector>

#include "tonus/protocol/payloads.hpp"

namespace tonus::host {

double TimeSyncSample::round_trip_us() const {
  return static_cast<double>(t4_host_us - t1_host_us) - static_cast<double>(t3_device_us - t2_device_us);
}

double TimeSyncSample::offset_us() const {
  // Differences first: the clocks' absolute values are large, their gaps small.
  const double a = static_cast<double>(static_cast<std::int64_t>(t2_device_us) - t1_host_us);
  const double b = static_cast<double>(static_cast<std::int64_t>(t3_device_us) - t4_host_us);
  return 0.5 * (a + b);
}

bool ClockSync::add(const TimeSyncSample& s) {
  if (s.t4_host_us < s.t1_host_us || s.t3_device_us < s.t2_device_us || s.round_trip_us() < 0.0 ||
      s.round_trip_us() > opt_.max_round_trip_us) {
    ++rejected_;
    return false;
  }
  samples_.push_back(s);
  while (samples_.size() > opt_.window) samples_.pop_front();
  min_rtt_us_ = samples_.size() == 1 ? s.round_trip_us() : std::min(min_rtt_us_, s.round_trip_us());
  last_device_us_ = s.t3_device_us;
  refit();
  return true;
}

namespace {

struct Point {
  double h, v;  // host time, bound on the offset
};

struct Line {
  double ref = 0.0, value = 0.0, slope = 0.0;
  [[nodiscard]] double at(double h) const { return value + slope * (h - ref); }
};

Line least_squares(const std::vector<Point>& pts, bool with_slope) {
  Line l;
  for (const Point& p : pts) {
    l.ref += p.h;
    l.value += p.v;
  }
  l.ref /= static_cast<double>(pts.size());
  l.value /= static_cast<double>(pts.size());
  double shh = 0.0, shv = 0.0;
  for (const Point& p : pts) {
    shh += (p.h - l.ref) * (p.h - l.ref);
    shv += (p.h - l.ref) * (p.v - l.value);
  }
  l.slope = with_slope && shh > 0.0 ? shv / shh : 0.0;
  return l;
}

// A least-squares line, fitted again without the points beyond 3 robust sigmas
// (a group whose best exchange was still delayed).
Line robust_fit(const std::vector<Point>& pts, bool with_slope) {
  Line l = least_squares(pts, with_slope);
  std::vector<double> residuals;
  residuals.reserve(pts.size());
  for (const Point& p : pts) residuals.push_back(std::abs(p.v - l.at(p.h)));
  std::vector<double> sorted = residuals;
  const auto mid = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
  std::nth_element(sorted.begin(), mid, sorted.end());
  const double limit = std::max(3.0 * 1.4826 * *mid, 10.0);
  std::vector<Point> inliers;
  for (std::size_t k = 0; k < pts.size(); ++k) {
    if (residuals[k] <= limit) inliers.push_back(pts[k]);
  }
  if (inliers.size() >= 3 && inliers.size() < pts.size()) l = least_squares(inliers, with_slope);
  return l;
}

}  // namespace

void ClockSync::refit() {
  // Each exchange bounds the offset: t3 - t4 <= offset <= t2 - t1. In each group
  // the tightest upper bound (least request delay) and the tightest lower bound
  // (least response delay) are kept, each from whichever exchange gave it.
  std::vector<Point> upper, lower;
  const std::size_t group = std::max<std::size_t>(opt_.group, 1);
  for (std::size_t first = 0; first < samples_.size(); first += group) {
    const std::size_t last = std::min(first + group, samples_.size());
    // A young group has had few chances at a tight bound: it waits to fill up.
    if (first > 0 && last - first < (group + 1) / 2) break;
    Point u{0.0, 0.0}, l{0.0, 0.0};
    for (std::size_t k = first; k < last; ++k) {
      const TimeSyncSample& s = samples_[k];
      const Point pu{static_cast<double>(s.t1_host_us),
                     static_cast<double>(static_cast<std::int64_t>(s.t2_device_us) - s.t1_host_us)};
      const Point pl{static_cast<double>(s.t4_host_us),
                     static_cast<double>(static_cast<std::int64_t>(s.t3_device_us) - s.t4_host_us)};
      if (k == first || pu.v < u.v) u = pu;
      if (k == first || pl.v > l.v) l = pl;
    }
    upper.push_back(u);
    lower.push_back(l);
  }
  const double span = samples_.back().host_mid_us() - samples_.front().host_mid_us();
  const bool with_drift = upper.size() >= 4 && span >= opt_.min_span_us;
  if (!with_drift) {
    // Too short to see drift: one group of everything.
    upper = {*std::min_element(upper.begin(), upper.end(), [](Point a, Point b) { return a.v < b.v; })};
    lower = {*std::max_element(lower.begin(), lower.end(), [](Point a, Point b) { return a.v < b.v; })};
  }
  const Line up = robust_fit(upper, with_drift);
  const Line low = robust_fit(lower, with_drift);
  // The offset runs midway between the two envelopes.
  ref_host_us_ = 0.5 * (up.ref + low.ref);
  offset_us_ = 0.5 * (up.at(ref_host_us_) + low.at(ref_host_us_));
  drift_ = 0.5 * (up.slope + low.slope);
  fitted_ = true;
}

double ClockSync::host_from_device_us(double device_us) const {
  // device = h + offset_us_ + drift_ * (h - ref), solved for h.
  return (device_us - offset_us_ + drift_ * ref_host_us_) / (1.0 + drift_);
}

std::uint64_t ClockSync::extend(std::uint32_t device_time_us) const {
  const auto low = static_cast<std::uint32_t>(last_device_us_);
  const auto step = static_cast<std::int32_t>(device_time_us - low);
  return static_cast<std::uint64_t>(static_cast<std::int64_t>(last_device_us_) + step);
}

std::optional<TimeSyncSample> exchange_time_sync(BandLink& link, std::uint8_t token, int timeout_ms,
                                                 const BandLink::StreamSink& sink, std::chrono::microseconds dither) {
  if (dither.count() > 0) {
    // A random phase against the band's poll and USB frame cycles (see the header).
    thread_local std::mt19937 rng{std::random_device{}()};
    std::uniform_int_distribution<std::int64_t> wait(0, dither.count());
    std::this_thread::sleep_for(std::chrono::microseconds(wait(rng)));
  }
  TimeSyncSample s;
  s.t1_host_us = steady_now_us();
  proto::Request req{};
  if (proto::make_request(proto::Opcode::time_sync, token,
                          proto::TimeSyncRequest{static_cast<std::uint64_t>(s.t1_host_us)}, req) != proto::Error::ok) {
    return std::nullopt;
  }
  std::int64_t t4 = 0;
  const auto rsp = link.transact(req, timeout_ms, sink, &t4);
  if (!rsp || rsp->status != proto::Status::ok) return std::nullopt;
  proto::TimeSyncResponse ts{};
  if (proto::read_payload(*rsp, ts) != proto::Error::ok) return std::nullopt;
  // The echo must be ours: a late answer to an earlier request would pair the wrong t1.
  if (ts.host_time_us != static_cast<std::uint64_t>(s.t1_host_us)) return std::nullopt;
  s.t2_device_us = ts.device_rx_us;
  s.t3_device_us = ts.device_tx_us;
  s.t4_host_us = t4;
  return s;
}

}  // namespace tonus::host
