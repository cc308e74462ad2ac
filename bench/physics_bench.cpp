// The physics step against MuJoCo on the same scene, in one run: the default
// humanoid standing on the ground with stiff drives (a 40 Hz hold, so it
// stands like a statue on its own), feet and toes on the ground, a 1 kg cube
// resting on its left hand, dt = 1 ms. MuJoCo runs the MJCF export of exactly
// that (drives as joint springs toward the standing pose, the same cube).
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <string>

#include "forwarding_reporter.hpp"
#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/mjcf.hpp"
#include "tonus/sim/objects.hpp"
#include "tonus/sim/step.hpp"

namespace {

using namespace tonus::sim;

constexpr int kSettleSteps = 500;

struct Scene {
  std::unique_ptr<Model> model;
  std::unique_ptr<Data> data;
  StepInputs inputs;
};

std::unique_ptr<Model> standing_humanoid() {
  HumanoidSpec spec;
  spec.drive_frequency_hz = 40.0;
  BuildResult r = build_humanoid(spec);
  if (!r) {
    std::fprintf(stderr, "tonus-bench-physics: %s\n", r.error.c_str());
    std::exit(1);
  }
  return std::move(r.model);
}

void add_cube_on_hand(const Model& m, Data& d) {
  const std::size_t hand = index(Bone::LeftHand);
  const Pose& x = d.xgeom[hand];
  ObjectSpec cube;
  cube.shape = Shape::box(Vec3::Constant(0.04));
  cube.mass_kg = 1.0;
  cube.pos = x.pos + Vec3(0, 0, m.geoms[hand].shape.half_extents_m.z() + 0.04 + 0.002);
  if (add_object(d, cube).error != ObjectError::none) std::exit(1);
}

Scene standing_scene() {
  Scene s;
  s.model = standing_humanoid();
  s.data = make_data(*s.model);
  s.inputs = make_inputs(*s.model);
  add_cube_on_hand(*s.model, *s.data);
  for (int i = 0; i < kSettleSteps; ++i) step(*s.model, *s.data, s.inputs);
  return s;
}

void BM_HumanoidStep(benchmark::State& state) {
  Scene s = standing_scene();
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    step(*s.model, *s.data, s.inputs);
    benchmark::DoNotOptimize(s.data->qpos.data());
  }
  state.counters["contacts"] = s.data->ncon;
  state.counters["solver_iterations"] = s.data->diag.solver_iterations;
  if (s.data->status == StepStatus::diverged) state.SkipWithError("the scene diverged");
}
BENCHMARK(BM_HumanoidStep);

// The dual PD tick: simulation A (kinematic root, stiff drives, no objects)
// tracks the reference and its applied PD torque is simulation B's
// feedforward; B (free root, weak drives, the cube) feeds the avatar.
void BM_DualTick(benchmark::State& state) {
  Scene b = standing_scene();
  const Model& m = *b.model;
  auto a = make_data(m);
  set_root_mode(*a, RootMode::kinematic);
  StepInputs in_a = make_inputs(m);
  for (int i = 0; i < m.nbody; ++i) {
    scale_joint_gains(m, in_a, i, 10.0, 1.0);
    scale_joint_gains(m, b.inputs, i, 0.1, 1.0);
  }
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    step(m, *a, in_a);
    for (int k = 6; k < m.nv; ++k) {
      const auto ku = static_cast<std::size_t>(k);
      b.inputs.tau_ff[ku] = a->tau_pd[ku] + a->tau_ff[ku];
    }
    step(m, *b.data, b.inputs);
    benchmark::DoNotOptimize(b.data->qpos.data());
  }
}
BENCHMARK(BM_DualTick);

void BM_MujocoStep(benchmark::State& state) {
  const auto model = standing_humanoid();
  auto data = make_data(*model);
  add_cube_on_hand(*model, *data);
  MjcfOptions opt;
  opt.drives_as_springs = true;
  opt.objects_from = data.get();
  char path[] = "/tmp/tonus-bench-XXXXXX.xml";
  const int fd = mkstemps(path, 4);
  if (fd < 0) {
    state.SkipWithError("no temporary file");
    return;
  }
  close(fd);
  std::ofstream(path) << to_mjcf(*model, opt);
  char err[1024] = {0};
  mjModel* mm = mj_loadXML(path, nullptr, err, sizeof err);
  std::remove(path);
  if (mm == nullptr) {
    state.SkipWithError(err);
    return;
  }
  mjData* md = mj_makeData(mm);
  for (int i = 0; i < kSettleSteps; ++i) mj_step(mm, md);
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    mj_step(mm, md);
    benchmark::DoNotOptimize(md->qpos);
  }
  state.counters["contacts"] = md->ncon;
  mj_deleteData(md);
  mj_deleteModel(mm);
}
BENCHMARK(BM_MujocoStep);

// Keeps each run's time (the mean over repetitions when there are several, else the run).
class RatioReporter : public tonus::bench::ForwardingReporter {
 public:
  using ForwardingReporter::ForwardingReporter;
  struct Times {
    double real_s = 0.0, cpu_s = 0.0;
    bool from_mean = false;
  };
  [[nodiscard]] Times times(const std::string& name) const {
    const auto it = times_.find(name);
    return it == times_.end() ? Times{} : it->second;
  }

 protected:
  void keep(const Run& r) override {
    const std::string& name = r.run_name.function_name;
    if (r.run_type == Run::RT_Aggregate && r.aggregate_name == "mean") {
      times_[name] = {r.GetAdjustedRealTime() * unit_seconds(r.time_unit),
                      r.GetAdjustedCPUTime() * unit_seconds(r.time_unit), true};
    } else if (r.run_type == Run::RT_Iteration && !times_[name].from_mean && r.repetition_index <= 0) {
      const auto n = static_cast<double>(r.iterations);
      times_[name] = {r.real_accumulated_time / n, r.cpu_accumulated_time / n, false};
    }
  }

 private:
  std::map<std::string, Times> times_;
};

}  // namespace

int main(int argc, char** argv) {
  bool json = false;
  for (int i = 1; i < argc; ++i) json = json || std::string(argv[i]) == "--benchmark_format=json";
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter(json);
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  std::ostream& out = json ? std::cerr : std::cout;
  const auto ours = reporter.times("BM_HumanoidStep"), dual = reporter.times("BM_DualTick");
  const auto mujoco = reporter.times("BM_MujocoStep");
  if (ours.real_s > 0.0 && mujoco.real_s > 0.0) {
    out << "\nstep time, tonus / MuJoCo (goal: at most 2, i.e. at least 0.5x MuJoCo's speed):\n"
        << "  wall: " << ours.real_s / mujoco.real_s << " (" << ours.real_s * 1e6 << " us vs " << mujoco.real_s * 1e6
        << " us)\n"
        << "  cpu:  " << ours.cpu_s / mujoco.cpu_s << " (" << ours.cpu_s * 1e6 << " us vs " << mujoco.cpu_s * 1e6
        << " us)\n";
    if (dual.real_s > 0.0) {
      out << "dual tick (two steps): " << dual.real_s * 1e6 << " us wall = " << dual.real_s / mujoco.real_s
          << " MuJoCo steps\n";
    }
  }
  out << "memory: sizeof(Model) = " << sizeof(Model) << " B, sizeof(Data) = " << sizeof(Data) << " B\n";
  return 0;
}
