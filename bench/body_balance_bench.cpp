// The online balance filter on a streamed performer body (reference::BodyBalance,
// tonusd's tracker.balance = "online" on a VMC performer): one push per
// iteration, the sender's skeleton posed, the filter's window, the corrected
// root and legs turned back into local rotations. The stream is what a sender
// with the humanoid's own skeleton (a VRM's normalised rig) sends for a real
// clip retargeted onto it: the CMU walk at 120 Hz, the Bandai kicks at 30 Hz.
// Goal (issue 14's online filter): at most 1 ms per frame at 120 Hz.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "tonus/host/reference/body_balance.hpp"
#include "tonus/host/reference/clip_reference.hpp"
#include "tonus/sim/data.hpp"
#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/step.hpp"

namespace {

using namespace tonus;

void body_balance(benchmark::State& state, const std::string& path) {
  const sim::BuildResult built = sim::build_humanoid(sim::HumanoidSpec{});
  if (!built) {
    state.SkipWithError(built.error.c_str());
    return;
  }
  const sim::Model& model = *built.model;
  const reference::ClipReference clip = reference::clip_to_reference(model, path);
  if (!clip.ok()) {
    state.SkipWithError(clip.error.c_str());
    return;
  }
  // The sender's samples: the humanoid posed frame by frame.
  const std::unique_ptr<sim::Data> data = sim::make_data(model);
  std::vector<reference::BodySample> samples(clip.qpos.size());
  for (std::size_t f = 0; f < clip.qpos.size(); ++f) {
    data->qpos = clip.qpos[f];
    sim::forward_kinematics(model, *data);
    reference::BodySample& s = samples[f];
    for (std::size_t i = 1; i < sim::kBoneCount; ++i) {
      s.present[i] = true;
      s.local[i] = data->xquat[sim::index(*sim::kBones[i].parent)].conjugate() * data->xquat[i];
    }
    s.root_present = true;
    s.root_position = data->xbody[0].pos;
    s.root_rotation = data->xquat[0];
  }
  balance::OnlineOptions o;
  o.dt_s = clip.dt_s;
  reference::BodyBalance::Created made = reference::BodyBalance::create(reference::skeleton_of(model), o);
  if (!made) {
    state.SkipWithError(made.error.c_str());
    return;
  }
  reference::BodyBalance& b = *made.balance;
  reference::BodySample out;
  std::vector<double> us;
  us.reserve(1 << 16);
  std::size_t t = 0;
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(b.push(samples[t], out));
    if (us.size() < us.capacity()) {
      us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count());
    }
    t = (t + 1) % samples.size();
  }
  std::sort(us.begin(), us.end());
  if (!us.empty()) {
    state.counters["p99_us"] = us[us.size() * 99 / 100];
    state.counters["max_us"] = us.back();
  }
  state.counters["lookahead_frames"] = static_cast<double>(b.lookahead_frames());
  state.counters["rate_hz"] = 1.0 / clip.dt_s;
}

}  // namespace

BENCHMARK_CAPTURE(body_balance, cmu_walk_120hz, std::string(TONUS_SOURCE_DIR) + "/tests/data/cmu_02_walk.bvh")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(body_balance, bandai_kicks_30hz,
                  std::string(TONUS_SHARED_DATA_DIR) + "/bvh/dataset-1_kick_normal_001.bvh")
    ->Unit(benchmark::kMicrosecond);
