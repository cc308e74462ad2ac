// The daemon's plumbing: the triple buffer under two threads, and the
// histogram's quantiles against a sort of the same values.
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>
#include <thread>
#include <vector>

#include "tonus/host/daemon/histogram.hpp"
#include "tonus/host/daemon/triple_buffer.hpp"

using namespace tonus::daemon;

TEST_CASE("triple buffer: the reader always sees a whole value, newer than the last, never a torn one") {
  struct Value {
    std::uint64_t a = 0;
    std::array<std::uint64_t, 32> copies{};
  };
  TripleBuffer<Value> tb;
  constexpr std::uint64_t kWrites = 200000;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (std::uint64_t i = 1; i <= kWrites; ++i) {
      Value& v = tb.write_slot();
      v.a = i;
      v.copies.fill(i);
      tb.publish();
    }
    done.store(true);
  });
  std::uint64_t last = 0, reads = 0, torn = 0, backwards = 0;
  for (;;) {
    const bool finished = done.load();  // read before update(): nothing published after it is missed
    if (!tb.update()) {
      if (finished) break;
      continue;
    }
    const Value& v = tb.read_slot();
    ++reads;
    if (std::any_of(v.copies.begin(), v.copies.end(), [&](std::uint64_t c) { return c != v.a; })) ++torn;
    if (v.a <= last) ++backwards;
    last = v.a;
  }
  writer.join();
  CHECK(last == kWrites);  // the last value published is always read
  CHECK(reads > 0);
  CHECK(torn == 0);
  CHECK(backwards == 0);
}

TEST_CASE("triple buffer: nothing new, nothing taken") {
  TripleBuffer<int> tb;
  CHECK_FALSE(tb.update());
  tb.write_slot() = 7;
  tb.publish();
  CHECK(tb.update());
  CHECK(tb.read_slot() == 7);
  CHECK_FALSE(tb.update());
  CHECK(tb.read_slot() == 7);
}

TEST_CASE("histogram quantiles match the sorted values to one bin, the overflow keeps the tail") {
  std::mt19937 rng(5);
  std::lognormal_distribution<double> dist(3.5, 0.6);  // tick-cost-like: ~33 us median, a long tail
  Histogram h(1.0, 200);
  std::vector<double> v;
  for (int i = 0; i < 50000; ++i) {
    const double x = dist(rng);
    v.push_back(x);
    h.add(x);
  }
  std::sort(v.begin(), v.end());
  for (const double q : {0.5, 0.9, 0.99}) {
    const double want = v[static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size()))) - 1];
    CHECK(h.quantile_us(q) >= want);
    CHECK(h.quantile_us(q) <= want + 1.0);
  }
  CHECK(h.max_us() == doctest::Approx(v.back()));
  CHECK(h.overflow() ==
        static_cast<std::uint64_t>(std::count_if(v.begin(), v.end(), [](double x) { return x >= 200; })));
  CHECK(h.quantile_us(1.0) == doctest::Approx(v.back()));
  CHECK(h.count_above(100.0) ==
        static_cast<std::uint64_t>(std::count_if(v.begin(), v.end(), [](double x) { return x >= 100.0; })));
  h.add(std::nan(""));
  h.add(-5.0);
  CHECK(h.count() == 50002);
  Histogram empty(1.0, 10);
  CHECK(empty.quantile_us(0.5) == 0.0);
}
