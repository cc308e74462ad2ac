// Time sync: the estimate of the band's clock checked against the truth, a
// device clock with a known offset and drift (synthetic, then tonus-band-sim
// --clock-offset-us/--clock-drift-ppm), never against the estimator itself.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <vector>

#include "sim_process.hpp"
#include "tonus/host/transport/time_sync.hpp"

using namespace tonus;
using namespace std::chrono_literals;

namespace {

struct ErrorStats {
  std::vector<double> abs_us;
  void add(double e) { abs_us.push_back(std::abs(e)); }
  [[nodiscard]] double mean() const {
    double s = 0.0;
    for (const double e : abs_us) s += e;
    return abs_us.empty() ? 0.0 : s / static_cast<double>(abs_us.size());
  }
  [[nodiscard]] double quantile(double q) const {
    if (abs_us.empty()) return 0.0;
    std::vector<double> v = abs_us;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
  }
  [[nodiscard]] double max() const { return abs_us.empty() ? 0.0 : *std::max_element(abs_us.begin(), abs_us.end()); }
};

}  // namespace

TEST_CASE("time sync: offset and drift through asymmetric, heavy-tailed delays (synthetic truth)") {
  // Device clock = X + h (1 + D). The band answers on its next 1 ms poll (a uniform wait, the
  // requests being dithered), both ways add exponential queueing, and 5 % of the exchanges
  // meet a scheduling hiccup of up to 5 ms in either direction: round trips from ~40 us to
  // several ms, as measured over a Unix socket.
  const double X = -3.2e11, D = 80e-6;
  const auto device_at = [&](double h) { return X + h * (1.0 + D); };
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> poll_wait(0.0, 1000.0), hiccup(0.0, 5000.0), unit(0.0, 1.0);
  std::exponential_distribution<double> queue(1.0 / 30.0);
  host::ClockSync sync;
  ErrorStats err;
  double h = 4.1e11;               // host steady time, us
  for (int k = 0; k < 500; ++k) {  // 20 s at 25 Hz
    h += 40000.0;
    host::TimeSyncSample s;
    double d_req = 20.0 + poll_wait(rng) + queue(rng);
    double d_rsp = 15.0 + queue(rng);
    if (unit(rng) < 0.05) (unit(rng) < 0.5 ? d_req : d_rsp) += hiccup(rng);
    s.t1_host_us = static_cast<std::int64_t>(h);
    s.t2_device_us = static_cast<std::uint64_t>(device_at(h + d_req));
    s.t3_device_us = s.t2_device_us + 4;
    s.t4_host_us = static_cast<std::int64_t>(h + d_req + 4.0 + d_rsp);
    REQUIRE(sync.add(s));
    if (k >= 50) {  // after 2 s: map a device time of "now" back and compare
      const double truth = h + 20000.0;
      err.add(sync.host_from_device_us(device_at(truth)) - truth);
    }
  }
  MESSAGE("synthetic: |error| mean " << err.mean() << " us, p99 " << err.quantile(0.99) << " us, max " << err.max()
                                     << " us; drift " << sync.drift_ppm() << " ppm (true 80)");
  CHECK(err.max() < 150.0);
  CHECK(sync.drift_ppm() == doctest::Approx(80.0).epsilon(0.1));

  // Inconsistent exchanges are refused, not fitted.
  host::TimeSyncSample bad;
  bad.t1_host_us = 10;
  bad.t4_host_us = 5;  // answered before it was asked
  CHECK_FALSE(sync.add(bad));
  bad.t4_host_us = 20;
  bad.t2_device_us = 9;
  bad.t3_device_us = 8;  // sent before it was received
  CHECK_FALSE(sync.add(bad));
  CHECK(sync.rejected() == 2);
}

TEST_CASE("time sync: the stream's 32-bit time extends to the clock of the exchanges") {
  host::ClockSync sync;
  host::TimeSyncSample s;
  s.t1_host_us = 100;
  s.t4_host_us = 300;
  s.t2_device_us = 0x300000000ULL - 50;  // just before a 2^32 wrap of the stream's field
  s.t3_device_us = s.t2_device_us + 10;
  REQUIRE(sync.add(s));
  CHECK(sync.extend(0xFFFFFFF0U) == 0x2FFFFFFF0ULL);
  CHECK(sync.extend(0x00000010U) == 0x300000010ULL);  // after the wrap
}

TEST_CASE("time sync against tonus-band-sim in real time: error under 1 ms, measured against its true clock") {
  // The simulated band's clock reads X + h (1 + D) at host steady time h: the truth.
  const double drift_ppm = 80.0;
  const double D = drift_ppm * 1e-6;
  const auto h0 = static_cast<double>(host::steady_now_us());
  const auto X = static_cast<std::int64_t>(-h0 * (1.0 + D) + 5e6);  // the band's clock starts near 5 s
  const std::string path =
      (std::filesystem::temp_directory_path() / ("tonus-sync-" + std::to_string(::getpid()) + ".sock")).string();
  test::SimProcess sim({"--synthetic", "rest", "--seconds", "8", "--quiet", "--hid-socket", path, "--clock-offset-us",
                        std::to_string(X), "--clock-drift-ppm", std::to_string(drift_ppm)});
  REQUIRE(sim.started());
  std::string error;
  const std::unique_ptr<host::SeqpacketHidTransport> t = test::connect_hid(path, error);
  REQUIRE_MESSAGE(t, error);
  host::HidBandLink link(*t);
  host::ClockSync sync;
  ErrorStats err, naive;
  std::vector<double> rtt;
  std::optional<host::TimeSyncSample> last;
  double first_exchange_h = 0.0;
  const auto on_report = [&](const proto::StreamMessage& m) {
    if (!sync.ready() || static_cast<double>(host::steady_now_us()) - first_exchange_h < 2e6) return;
    const double device = static_cast<double>(sync.extend(m.device_time_us));
    const double truth = (device - static_cast<double>(X)) / (1.0 + D);
    err.add(sync.host_from_device_us(device) - truth);
    naive.add(device - last->offset_us() - truth);  // the latest exchange alone, for comparison
  };
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> gap_ms(20, 50);
  auto next_exchange = std::chrono::steady_clock::now();
  std::uint8_t token = 1;
  for (;;) {
    if (std::chrono::steady_clock::now() >= next_exchange) {
      const auto s = host::exchange_time_sync(link, token++, 500, on_report);
      if (s) {
        if (first_exchange_h == 0.0) first_exchange_h = static_cast<double>(s->t1_host_us);
        sync.add(*s);
        rtt.push_back(s->round_trip_us());
        last = s;
      }
      next_exchange = std::chrono::steady_clock::now() + std::chrono::milliseconds(gap_ms(rng));
    }
    const host::LinkEvent e = link.poll(5);
    if (e.kind == host::LinkEvent::Kind::closed) break;
    if (e.kind == host::LinkEvent::Kind::stream) on_report(e.stream);
  }
  std::sort(rtt.begin(), rtt.end());
  REQUIRE(rtt.size() > 100);
  REQUIRE(err.abs_us.size() > 1500);  // 6 s of reports at >= 250 Hz
  MESSAGE("sim (" << rtt.size() << " exchanges, round trip min " << rtt.front() << " us, median " << rtt[rtt.size() / 2]
                  << " us, max " << rtt.back() << " us; " << err.abs_us.size() << " reports): |error| mean "
                  << err.mean() << " us, p99 " << err.quantile(0.99) << " us, max " << err.max() << " us; drift "
                  << sync.drift_ppm() << " ppm (true " << drift_ppm << "); latest exchange alone: mean " << naive.mean()
                  << " us, max " << naive.max() << " us");
  CHECK(err.max() < 1000.0);
  CHECK(err.quantile(0.99) < 500.0);
  CHECK(sync.drift_ppm() == doctest::Approx(drift_ppm).epsilon(0.25));
  CHECK(sim.wait(5s) == 0);
}
