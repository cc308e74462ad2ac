// Throughput of the ZMP analysis and of the balance filter, in frames per
// second, on the bundled CMU walk (120 Hz) and the Bandai Namco walk (30 Hz)
// when ../shared/data is there.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "tonus/host/balance/analysis.hpp"
#include "tonus/host/balance/convert.hpp"
#include "tonus/host/balance/filter.hpp"
#include "tonus/host/balance/online_filter.hpp"
#include "tonus/host/balance/robust_filter.hpp"
#include "tonus/host/motion/bvh.hpp"

namespace {

using namespace tonus;

balance::HumanMotion load(const std::string& path, bool& ok) {
  const motion::ReadResult r = motion::read_bvh_file(path);
  ok = r.ok();
  if (!ok) return {};
  const balance::Conversion c = balance::convert_motion(r.clip, balance::map_skeleton(r.clip), {});
  ok = c.ok();
  return c.motion;
}

void analyse(benchmark::State& state, const std::string& path) {
  bool ok = false;
  const balance::HumanMotion m = load(path, ok);
  if (!ok) {
    state.SkipWithError("clip not readable");
    return;
  }
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    benchmark::DoNotOptimize(balance::analyse(m, balance::AnalysisOptions{}));
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(m.size()));
  state.counters["frames"] = static_cast<double>(m.size());
}

void filter(benchmark::State& state, const std::string& path) {
  bool ok = false;
  const balance::HumanMotion m = load(path, ok);
  if (!ok) {
    state.SkipWithError("clip not readable");
    return;
  }
  std::size_t band = 0, iterations = 0;
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    const balance::FilterResult f = balance::balance_filter(m, balance::FilterOptions{});
    band = f.operator_band;
    iterations = static_cast<std::size_t>(f.iterations);
    benchmark::DoNotOptimize(f.correction.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(m.size()));
  state.counters["frames"] = static_cast<double>(m.size());
  state.counters["lookahead_frames"] = static_cast<double>(band);
  state.counters["solver_iterations"] = static_cast<double>(iterations);
}

void robust_filter(benchmark::State& state, const std::string& path, bool both_trunks) {
  bool ok = false;
  const balance::HumanMotion m = load(path, ok);
  if (!ok) {
    state.SkipWithError("clip not readable");
    return;
  }
  std::size_t lookahead = 0, iterations = 0, worst = 0;
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    balance::RobustFilterOptions options;
    options.both_trunks = both_trunks;  // the family with the trunk along the spine and straight
    const balance::RobustFilterResult f = balance::robust_balance_filter(m, options);
    lookahead = f.lookahead_frames;
    iterations = static_cast<std::size_t>(f.iterations);
    worst = f.verdict_after.members.empty() ? 0 : f.verdict_after.members[f.verdict_after.worst].outside;
    benchmark::DoNotOptimize(f.rotation.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(m.size()));
  state.counters["frames"] = static_cast<double>(m.size());
  state.counters["lookahead_frames"] = static_cast<double>(lookahead);
  state.counters["solver_iterations"] = static_cast<double>(iterations);
  state.counters["worst_member_outside"] = static_cast<double>(worst);
}

// The streaming filter: one push per iteration (the clip played in a loop),
// with the tail of the per-frame cost beside Google Benchmark's mean.
void online_filter(benchmark::State& state, const std::string& path) {
  bool ok = false;
  const balance::HumanMotion m = load(path, ok);
  if (!ok) {
    state.SkipWithError("clip not readable");
    return;
  }
  balance::OnlineOptions o;
  o.dt_s = m.dt_s;
  auto created = balance::OnlineBalance::create(o);
  if (!created) {
    state.SkipWithError(created.error.c_str());
    return;
  }
  balance::OnlineBalance& f = *created.filter;
  balance::OnlineFrame out;
  std::vector<double> us;
  us.reserve(1 << 16);
  std::size_t t = 0;
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(f.push(m.frames[t], out));
    if (us.size() < us.capacity()) {
      us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    }
    t = (t + 1) % m.size();
  }
  std::sort(us.begin(), us.end());
  if (!us.empty()) {
    state.counters["p99_us"] = us[us.size() * 99 / 100];
    state.counters["max_us"] = us.back();
  }
  state.counters["lookahead_frames"] = static_cast<double>(f.lookahead_frames());
  state.counters["rate_hz"] = 1.0 / m.dt_s;
}

const std::string kCmuWalk = std::string(TONUS_SOURCE_DIR) + "/tests/data/cmu_02_walk.bvh";
const std::string kBandaiWalk = std::string(TONUS_SHARED_DATA_DIR) + "/bvh/dataset-1_walk_normal_001.bvh";

}  // namespace

BENCHMARK_CAPTURE(analyse, cmu_walk_120hz, kCmuWalk)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(analyse, bandai_walk_30hz, kBandaiWalk)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(filter, cmu_walk_120hz, kCmuWalk)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(filter, bandai_walk_30hz, kBandaiWalk)->Unit(benchmark::kMillisecond);

BENCHMARK_CAPTURE(robust_filter, cmu_walk_120hz, kCmuWalk, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(robust_filter, bandai_walk_30hz, kBandaiWalk, false)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(robust_filter, cmu_walk_120hz_both_trunks, kCmuWalk, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(robust_filter, bandai_walk_30hz_both_trunks, kBandaiWalk, true)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(online_filter, cmu_walk_120hz, kCmuWalk)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(online_filter, bandai_kicks_30hz,
                  std::string(TONUS_SHARED_DATA_DIR) + "/bvh/dataset-1_kick_normal_001.bvh")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
