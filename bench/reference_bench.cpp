// One tracker IK solve (host/reference/tracker_ik.hpp), 3 and 6 points, on
// real walks: the bundled CMU walk (120 Hz) and, when ../shared/data is
// there, the Bandai Namco walk and the CMU jumps (the lively case). The
// tracker streams are the `tonus ik` evaluation's (tools/tonus/experiments);
// each iteration solves the next frame of the loop, so steps, clamps and the
// spine's reach are all in the figure. Goal: at most 20 us per solve.
// slowest_frame_us: the slowest frame's median solve (see below).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "experiments/ik_eval.hpp"

namespace {

using namespace tonus;

// One solve of the clip's frame f at time t_s, timed on its own: seconds.
double timed_solve(const experiments::IkSetup& setup, reference::IkState& ik_state, reference::IkOutput& out,
                   std::size_t f, double t_s) {
  reference::TrackerFrame frame = setup.trackers[f];
  frame.time_s = t_s;
  const auto t0 = std::chrono::steady_clock::now();
  reference::solve_ik(*setup.ik, ik_state, frame, out);
  benchmark::DoNotOptimize(out.qpos.data());
  benchmark::ClobberMemory();
  const auto t1 = std::chrono::steady_clock::now();
  return std::chrono::duration<double>(t1 - t0).count();
}

// The clip's slowest frame by the median of its solves over repeated passes:
// whether a tail above the goal is a frame the solver finds hard (this figure
// above it too) or the machine interrupting solves at random (this figure low).
double slowest_frame_median_us(const experiments::IkSetup& setup) {
  constexpr std::size_t kPasses = 100;
  const std::size_t n = setup.trackers.size();
  std::vector<double> us(n * kPasses);
  reference::IkState ik_state;
  reference::IkOutput out;
  double t = 0.0;
  for (std::size_t pass = 0; pass < kPasses; ++pass) {
    for (std::size_t f = 0; f < n; ++f) {
      us[f * kPasses + pass] = 1e6 * timed_solve(setup, ik_state, out, f, t);
      t += setup.dt_s;
    }
  }
  double slowest = 0.0;
  for (std::size_t f = 0; f < n; ++f) {
    const auto first = us.begin() + static_cast<std::ptrdiff_t>(f * kPasses);
    const auto middle = first + static_cast<std::ptrdiff_t>(kPasses / 2);
    std::nth_element(first, middle, first + static_cast<std::ptrdiff_t>(kPasses));
    slowest = std::max(slowest, *middle);
  }
  return slowest;
}

void solve(benchmark::State& state, const std::string& clip, int trackers) {
  if (!std::filesystem::exists(clip)) {
    state.SkipWithError("clip not found");
    return;
  }
  experiments::IkEvalOptions opt;
  opt.clip = clip;
  opt.trackers = trackers;
  experiments::IkEvalResult r;
  const experiments::IkSetup setup = experiments::prepare_ik_eval(opt, r);
  if (!r.error.empty() || !setup.ik) {
    state.SkipWithError(r.error.c_str());
    return;
  }
  reference::IkState ik_state;
  reference::IkOutput out;
  std::size_t f = 0;
  double t = 0.0;
  // Each solve timed on its own (manual time), so the tails are per solve.
  std::vector<double> us;
  us.reserve(1 << 22);
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    const double s = timed_solve(setup, ik_state, out, f, t);
    state.SetIterationTime(s);
    if (us.size() < us.capacity()) us.push_back(1e6 * s);
    f = (f + 1) % setup.trackers.size();
    t += setup.dt_s;
  }
  std::sort(us.begin(), us.end());
  const auto at = [&](double q) {
    return us.empty() ? 0.0 : us[static_cast<std::size_t>(q * static_cast<double>(us.size() - 1))];
  };
  state.counters["p50_us"] = at(0.50);
  state.counters["p99_us"] = at(0.99);
  state.counters["max_us"] = us.empty() ? 0.0 : us.back();
  state.counters["frames"] = static_cast<double>(setup.trackers.size());
  state.counters["slowest_frame_us"] = slowest_frame_median_us(setup);
}

const std::string kCmuWalk = std::string(TONUS_SOURCE_DIR) + "/tests/data/cmu_02_walk.bvh";
const std::string kBandaiWalk = std::string(TONUS_SHARED_DATA_DIR) + "/bvh/dataset-1_walk_normal_001.bvh";
const std::string kJumps = std::string(TONUS_SHARED_DATA_DIR) + "/bvh/cmu_01_01_jumps.bvh";

BENCHMARK_CAPTURE(solve, cmu_walk_3, kCmuWalk, 3)->Unit(benchmark::kMicrosecond)->UseManualTime();
BENCHMARK_CAPTURE(solve, cmu_walk_6, kCmuWalk, 6)->Unit(benchmark::kMicrosecond)->UseManualTime();
BENCHMARK_CAPTURE(solve, bandai_walk_3, kBandaiWalk, 3)->Unit(benchmark::kMicrosecond)->UseManualTime();
BENCHMARK_CAPTURE(solve, bandai_walk_6, kBandaiWalk, 6)->Unit(benchmark::kMicrosecond)->UseManualTime();
BENCHMARK_CAPTURE(solve, cmu_jumps_3, kJumps, 3)->Unit(benchmark::kMicrosecond)->UseManualTime();
BENCHMARK_CAPTURE(solve, cmu_jumps_6, kJumps, 6)->Unit(benchmark::kMicrosecond)->UseManualTime();

}  // namespace

BENCHMARK_MAIN();
