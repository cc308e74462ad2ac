// The physics step of tonus::sim against MuJoCo's mj_step (2.2.2), in one run,
// on the five scenes of physics_scenes.hpp (static, lively, pile20, pile50,
// shower100; dt = 1 ms). MuJoCo runs the MJCF export of exactly the same
// scene (drives as joint springs toward the standing pose, the objects as
// free bodies) and the same teleports at the same step indices.
//
//   BM_Tonus/<scene>          one tonus step.
//   BM_Mujoco/<scene>         one mj_step with MuJoCo's defaults (Newton, pyramidal cone, tolerance 1e-8).
//   BM_MujocoMatched/<scene>  one mj_step with settings matched to tonus's accuracy (see calibrate()).
//   BM_DualTick               simulation A + simulation B of the dual PD scheme, static scene.
//   BM_TonusScaling/<boxes>   tonus on piles of 0..50 boxes, 2000 steps each: cost against contacts.
//
// Goals, per scene: tonus / MuJoCo <= 0.5 on the mean step time and <= 0.75
// on the 99th percentile. Every step is timed on its own (steady_clock around
// the step only; the teleports of the lively and shower scenes happen between
// samples): the counters mean_us, p50_us, p99_us and max_us, which the summary
// uses, are of the step alone (Google Benchmark's own time per iteration also
// holds the teleports and the two clock reads, well under 1 %). The summary
// after the runs prints the ratios, the solvers' statistics, the memory and
// the scaling fit (to stderr with --benchmark_format=json, so the JSON stays clean).
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <unistd.h>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <initializer_list>
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "forwarding_reporter.hpp"
#include "physics_scenes.hpp"
#include "tonus/sim/objects.hpp"
#include "tonus/sim/step.hpp"

namespace {

using namespace tonus::sim;
using tonus::bench::SceneSpec;
using tonus::bench::Teleport;
using tonus::bench::TonusScene;
using Clock = std::chrono::steady_clock;
using std::size_t;

constexpr double kResidualGoal = 1e-6;  // m/s: the velocity residual tonus's contact solve aims at
constexpr double kMeanGoal = 0.5, kP99Goal = 0.75;
constexpr std::array<int, 6> kScalingBoxes = {0, 5, 10, 20, 30, 50};
constexpr int kScalingSteps = 2000;

// Cases skipped with an error, and why (the summary lists them; Google
// Benchmark only passes the runs that worked to the reporter's keep()).
std::map<std::string, std::string>& skipped() {
  static std::map<std::string, std::string> s;
  return s;
}
void skip(benchmark::State& state, const std::string& name, const std::string& why) {
  skipped()[name] = why;
  state.SkipWithError(why.c_str());
}

// ------------------------------------------------------------ statistics --

// Per-step samples, allocated and zero-filled before the timed loop, so the
// loop neither allocates nor faults fresh pages in: it only writes into them.
class Samples {
 public:
  explicit Samples(benchmark::IterationCount n)
      : us_(static_cast<size_t>(n)), residual_(static_cast<size_t>(n)), iterations_(static_cast<size_t>(n)) {}

  void add(double us, int ncon, int iterations, double residual) {
    if (n_ == us_.size()) return;
    us_[n_] = us;
    residual_[n_] = residual;
    iterations_[n_] = iterations;
    contacts_ += ncon;
    ++n_;
  }

  // mean_us, p50_us, p99_us, max_us, contacts (mean per step).
  void report_times(benchmark::State& state) {
    if (n_ == 0) return;
    const double n = static_cast<double>(n_);
    double sum = 0.0;
    for (size_t i = 0; i < n_; ++i) sum += us_[i];
    state.counters["mean_us"] = sum / n;
    state.counters["p50_us"] = quantile(us_, 0.50);
    state.counters["p99_us"] = quantile(us_, 0.99);
    state.counters["max_us"] = quantile(us_, 1.0);
    state.counters["contacts"] = contacts_ / n;
  }

  // tonus: the residual (m/s) against kResidualGoal, and the sweeps.
  void report_tonus_solver(benchmark::State& state) {
    if (n_ == 0) return;
    size_t over = 0;
    for (size_t i = 0; i < n_; ++i) over += residual_[i] > kResidualGoal ? 1U : 0U;
    state.counters["residual_p99"] = quantile(residual_, 0.99);
    state.counters["residual_max"] = quantile(residual_, 1.0);
    state.counters["converged_frac"] = 1.0 - static_cast<double>(over) / static_cast<double>(n_);
    state.counters["unconverged"] = static_cast<double>(over);
    report_iterations(state);
  }

  // MuJoCo: its iterations and the scaled gradient its solver stopped at.
  void report_mujoco_solver(benchmark::State& state) {
    if (n_ == 0) return;
    state.counters["gradient_p99"] = quantile(residual_, 0.99);
    report_iterations(state);
  }

 private:
  void report_iterations(benchmark::State& state) {
    double sum = 0.0;
    for (size_t i = 0; i < n_; ++i) sum += iterations_[i];
    state.counters["iter_mean"] = sum / static_cast<double>(n_);
    state.counters["iter_p99"] = quantile(iterations_, 0.99);
  }
  // Sorts the filled part of v in place (after the timed loop).
  [[nodiscard]] double quantile(std::vector<double>& v, double q) const {
    const auto end = v.begin() + static_cast<std::ptrdiff_t>(n_);
    std::sort(v.begin(), end);
    const auto k = static_cast<size_t>(std::ceil(q * static_cast<double>(n_)));
    return v[std::min(std::max<size_t>(k, 1), n_) - 1];
  }

  std::vector<double> us_, residual_, iterations_;
  double contacts_ = 0.0;
  size_t n_ = 0;
};

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// ---------------------------------------------------------------- tonus --

// Google Benchmark runs a case several times while it picks the iteration
// count; the scene is built and settled once and then carries on (its
// schedule keeps cycling). One scene is kept at a time, to bound memory.
TonusScene& tonus_scene(const SceneSpec& spec) {
  static std::unique_ptr<TonusScene> cached;
  if (!cached || cached->spec.name != spec.name) {
    cached.reset();
    cached = std::make_unique<TonusScene>(tonus::bench::make_scene(spec));
    if (cached->error.empty()) cached->settle();
  }
  return *cached;
}

void BM_Tonus(benchmark::State& state, const SceneSpec& spec, const std::string& name) {
  TonusScene& s = tonus_scene(spec);
  if (!s.error.empty()) return skip(state, name, s.error);
  if (s.data->status == StepStatus::diverged) return skip(state, name, spec.name + ": tonus diverged while settling");
  const Model& m = *s.model;
  Data& d = *s.data;
  const Diagnostics before = d.diag;
  Samples samples(state.max_iterations);
  bool diverged = false;
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    s.put_back();
    const auto t0 = Clock::now();
    step(m, d, s.inputs);
    const auto t1 = Clock::now();
    ++s.next_step;
    samples.add(seconds(t1 - t0) * 1e6, d.ncon, d.diag.solver_iterations, d.diag.solver_residual);
    diverged = diverged || d.status == StepStatus::diverged;
  }
  if (diverged) return skip(state, name, spec.name + ": tonus diverged");
  samples.report_times(state);
  samples.report_tonus_solver(state);
  state.counters["contact_overflow"] = static_cast<double>(d.diag.contact_overflow - before.contact_overflow);
  state.counters["engine_unconverged"] = static_cast<double>(d.diag.solver_unconverged - before.solver_unconverged);
}

// The dual PD tick: simulation A (kinematic root, stiff drives, no objects)
// tracks the reference and its applied PD torque is simulation B's
// feedforward; B (free root, weak drives, the cube) feeds the avatar.
void BM_DualTick(benchmark::State& state) {
  const std::string name = "BM_DualTick";
  TonusScene b = tonus::bench::make_scene(tonus::bench::benchmark_scenes().front());
  if (!b.error.empty()) return skip(state, name, b.error);
  b.settle();
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
      const auto ku = static_cast<size_t>(k);
      b.inputs.tau_ff[ku] = a->tau_pd[ku] + a->tau_ff[ku];
    }
    step(m, *b.data, b.inputs);
    benchmark::DoNotOptimize(b.data->qpos.data());
  }
}

// --------------------------------------------------------------- MuJoCo --

struct MjDelete {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using MjModelPtr = std::unique_ptr<mjModel, MjDelete>;
using MjDataPtr = std::unique_ptr<mjData, MjDelete>;

// MuJoCo's copy of a scene, with the same schedule: object slot k is the free
// joint "object<k>" of the export.
struct MujocoScene {
  std::string key;  // variant:scene
  tonus::bench::Schedule schedule;
  MjModelPtr model;
  MjDataPtr data;
  std::array<std::pair<int, int>, kMaxObjects> object_adr{};  // slot -> (qpos, dof) address, -1 if absent
  std::int64_t next_step = 0;
  double qvel_error = 0.0;  // the largest end-of-step qvel error against a converged solve (calibrate())
  std::string error;

  void put_back(mjData* d) const {
    schedule.at(next_step, [&](const Teleport& t) {
      const auto [qa, da] = object_adr[static_cast<size_t>(t.slot)];
      if (qa < 0) return;
      mjtNum* q = d->qpos + qa;
      mjtNum* v = d->qvel + da;
      for (int i = 0; i < 3; ++i) {
        q[i] = t.pos[i];
        v[i] = t.lin_vel[i];
        v[i + 3] = 0.0;
      }
      q[3] = t.quat.w();
      q[4] = t.quat.x();
      q[5] = t.quat.y();
      q[6] = t.quat.z();
    });
  }
  void advance(mjData* d) {
    put_back(d);
    mj_step(model.get(), d);
    ++next_step;
  }
};

// The export asks for 2000 constraint rows and 500 contacts, which the pile
// and shower scenes can come close to (MuJoCo would then drop contacts and
// warn; counted as its contact_overflow). Not more: MuJoCo 2.2.2's mjData holds
// a dense njmax x njmax matrix (128 MB at 4000).
std::string roomier(std::string xml) {
  const std::string from = "<size njmax=\"2000\" nconmax=\"500\"/>";
  const auto at = xml.find(from);
  if (at != std::string::npos) xml.replace(at, from.size(), "<size njmax=\"4000\" nconmax=\"1000\"/>");
  return xml;
}

MjModelPtr load_mjcf(const std::string& xml, std::string& error) {
  char path[] = "/tmp/tonus-bench-XXXXXX.xml";
  const int fd = mkstemps(path, 4);
  if (fd < 0) {
    error = "no temporary file";
    return nullptr;
  }
  close(fd);
  std::ofstream(path) << roomier(xml);
  std::array<char, 1024> err{};
  MjModelPtr m(mj_loadXML(path, nullptr, err.data(), static_cast<int>(err.size())));
  std::remove(path);
  if (!m) error = std::string("mj_loadXML: ") + err.data();
  return m;
}

// What mj_step reads from mjData (this model has no actuators, mocap bodies
// or applied forces): saving and loading it repeats a step exactly.
struct MjState {
  std::vector<mjtNum> qpos, qvel, warmstart;
  mjtNum time = 0.0;
  void save(const mjModel* m, const mjData* d) {
    qpos.assign(d->qpos, d->qpos + m->nq);
    qvel.assign(d->qvel, d->qvel + m->nv);
    warmstart.assign(d->qacc_warmstart, d->qacc_warmstart + m->nv);
    time = d->time;
  }
  void load(mjData* d) const {
    std::copy(qpos.begin(), qpos.end(), d->qpos);
    std::copy(qvel.begin(), qvel.end(), d->qvel);
    std::copy(warmstart.begin(), warmstart.end(), d->qacc_warmstart);
    d->time = time;
  }
};

// MuJoCo's Newton solver stops when the scaled cost improvement or gradient
// falls under opt.tolerance, numbers with no direct relation to tonus's
// velocity residual. So the matched tolerance is measured: at kProbes states
// along the scene's cycle (the scene runs on from the settled state, with its
// teleports, and is put back afterwards), one step with each candidate
// tolerance is compared with a converged step from the same state (tolerance
// 1e-15, 1000 iterations); the loosest tolerance whose end-of-step qvel stays
// within 1e-6 (m/s for the free joints' linear part, rad/s for the rest) at
// every probe is kept. That bounds MuJoCo's true error, while tonus's residual
// is the complementarity error of its own solve: if anything, MuJoCo is held
// to the stricter standard. Returns the largest qvel error of each tolerance.
std::vector<double> qvel_errors(MujocoScene& s, const std::vector<double>& tolerances) {
  constexpr int kProbes = 16, kProbeSpacing = 37;  // 37 is prime to the 400- and 15-step cycles
  mjModel* m = s.model.get();
  mjData* d = s.data.get();
  const mjOption saved = m->opt;
  const std::int64_t settled_step = s.next_step;
  MjState settled, probe;
  settled.save(m, d);
  std::vector<double> worst(tolerances.size(), 0.0), converged(static_cast<size_t>(m->nv));
  for (int p = 0; p < kProbes; ++p) {
    for (int i = 0; i < kProbeSpacing; ++i) s.advance(d);
    s.put_back(d);  // the teleports due before this step, as the benchmark applies them
    probe.save(m, d);
    m->opt.tolerance = 1e-15;
    m->opt.iterations = 1000;
    mj_step(m, d);
    std::copy(d->qvel, d->qvel + m->nv, converged.begin());
    m->opt.iterations = saved.iterations;
    for (size_t c = 0; c < tolerances.size(); ++c) {
      m->opt.tolerance = tolerances[c];
      probe.load(d);
      mj_step(m, d);
      for (int i = 0; i < m->nv; ++i) {
        worst[c] = std::max(worst[c], std::abs(d->qvel[i] - converged[static_cast<size_t>(i)]));
      }
    }
    m->opt = saved;
    probe.load(d);
  }
  settled.load(d);
  s.next_step = settled_step;
  return worst;
}

double calibrate(MujocoScene& s) {
  const std::vector<double> candidates = {1e-3, 3e-4, 1e-4, 3e-5, 1e-5,  3e-6,  1e-6, 3e-7,
                                          1e-7, 3e-8, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
  const std::vector<double> err = qvel_errors(s, candidates);
  size_t pick = candidates.size() - 1;
  for (size_t c = 0; c < candidates.size(); ++c) {
    if (err[c] <= kResidualGoal) {
      pick = c;
      break;
    }
  }
  s.qvel_error = err[pick];
  return candidates[pick];
}

MujocoScene& mujoco_scene(const SceneSpec& spec, bool matched) {
  static std::unique_ptr<MujocoScene> cached;
  const std::string key = (matched ? "matched:" : "default:") + spec.name;
  if (cached && cached->key == key) return *cached;
  cached.reset();
  cached = std::make_unique<MujocoScene>();
  MujocoScene& s = *cached;
  s.key = key;
  TonusScene t = tonus::bench::make_scene(spec);  // not settled: its initial state is MuJoCo's
  s.error = t.error;
  if (!s.error.empty()) return s;
  s.schedule = t.schedule;
  s.model = load_mjcf(t.mjcf, s.error);
  if (!s.model) {
    s.error = spec.name + ": " + s.error;
    return s;
  }
  mjModel* m = s.model.get();
  for (size_t k = 0; k < kMaxObjects; ++k) {
    const int j = mj_name2id(m, mjOBJ_JOINT, ("object" + std::to_string(k)).c_str());
    s.object_adr[k] = j < 0 ? std::pair{-1, -1} : std::pair{m->jnt_qposadr[j], m->jnt_dofadr[j]};
  }
  if (matched) m->opt.cone = mjCONE_ELLIPTIC;  // tonus projects friction on the Coulomb disc
  s.data.reset(mj_makeData(m));
  while (s.next_step < spec.settle_steps) s.advance(s.data.get());
  if (matched) {
    m->opt.tolerance = calibrate(s);
  } else {
    s.qvel_error = qvel_errors(s, {m->opt.tolerance}).front();  // how accurate the defaults are, for the summary
  }
  return s;
}

int mj_warnings(const mjData* d, int w) { return d->warning[w].number; }

void BM_Mujoco(benchmark::State& state, const SceneSpec& spec, bool matched, const std::string& name) {
  MujocoScene& s = mujoco_scene(spec, matched);
  if (!s.error.empty()) return skip(state, name, s.error);
  mjModel* m = s.model.get();
  mjData* d = s.data.get();
  const int bad0 = mj_warnings(d, mjWARN_BADQACC);
  const int full0 = mj_warnings(d, mjWARN_CONTACTFULL) + mj_warnings(d, mjWARN_CNSTRFULL);
  if (bad0 > 0) return skip(state, name, spec.name + ": MuJoCo diverged while settling");
  Samples samples(state.max_iterations);
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    s.put_back(d);
    const auto t0 = Clock::now();
    mj_step(m, d);
    const auto t1 = Clock::now();
    ++s.next_step;
    const int it = std::min(d->solver_iter, static_cast<int>(mjNSOLVER));
    samples.add(seconds(t1 - t0) * 1e6, d->ncon, d->solver_iter,
                it > 0 ? d->solver[static_cast<size_t>(it - 1)].gradient : 0.0);
  }
  if (mj_warnings(d, mjWARN_BADQACC) > bad0) return skip(state, name, spec.name + ": MuJoCo diverged (bad qacc)");
  samples.report_times(state);
  samples.report_mujoco_solver(state);
  state.counters["contact_overflow"] = mj_warnings(d, mjWARN_CONTACTFULL) + mj_warnings(d, mjWARN_CNSTRFULL) - full0;
  state.counters["tolerance"] = m->opt.tolerance;
  state.counters["qvel_err"] = s.qvel_error;
}

// ------------------------------------------------------------ reporting --

// Forwards to the reporter the flags ask for and keeps each case's figures
// (the mean over repetitions when there are several, else the first run).
class SummaryReporter : public tonus::bench::ForwardingReporter {
 public:
  using ForwardingReporter::ForwardingReporter;
  using Figures = std::map<std::string, double>;  // "time_us" and every counter

  [[nodiscard]] const Figures* figures(const std::string& name) const {
    const auto it = figures_.find(name);
    return it == figures_.end() ? nullptr : &it->second.values;
  }

 protected:
  void keep(const Run& r) override {
    const std::string& name = r.run_name.function_name;
    const bool mean = r.run_type == Run::RT_Aggregate && r.aggregate_name == "mean";
    const bool first = r.run_type == Run::RT_Iteration && r.repetition_index <= 0 && !figures_.contains(name);
    if (!mean && !first) return;
    Kept& k = figures_[name];
    if (k.from_mean && !mean) return;
    k.from_mean = mean;
    k.values.clear();
    k.values["time_us"] = r.GetAdjustedRealTime() * unit_seconds(r.time_unit) * 1e6;
    for (const auto& [counter, value] : r.counters) k.values[counter] = value.value;
  }

 private:
  struct Kept {
    Figures values;
    bool from_mean = false;
  };
  std::map<std::string, Kept> figures_;
};

double get(const SummaryReporter::Figures* f, const char* key) {
  if (f == nullptr) return 0.0;
  const auto it = f->find(key);
  return it == f->end() ? 0.0 : it->second;
}

std::string ratio(double ours, double theirs, double goal) {
  if (ours <= 0.0 || theirs <= 0.0) return "    -          ";
  char s[64];
  std::snprintf(s, sizeof s, "%5.2f %-9s", ours / theirs, ours / theirs <= goal ? "(met)" : "(NOT met)");
  return s;
}

// True when some scene of these families ran (the tables are left out otherwise).
bool any_scene_ran(const SummaryReporter& rep, std::initializer_list<const char*> families) {
  for (const auto& spec : tonus::bench::benchmark_scenes()) {
    for (const char* family : families) {
      if (rep.figures(family + spec.name) != nullptr) return true;
    }
  }
  return false;
}

void print_times(const SummaryReporter& rep, std::ostream& out) {
  if (!any_scene_ran(rep, {"BM_Tonus/", "BM_Mujoco/", "BM_MujocoMatched/"})) return;
  char line[512];
  out << "\nstep time per scene, us (tonus / MuJoCo; goals: mean ratio <= " << kMeanGoal
      << ", p99 ratio <= " << kP99Goal << ")\n"
      << "  MuJoCo default: Newton, pyramidal cone, tolerance 1e-8. MuJoCo matched: elliptic cone (tonus's\n"
      << "  friction disc) and the loosest tolerance whose steps land within 1e-6 m/s (rad/s) of a converged\n"
      << "  solve at 16 states of the scene (the tolerance and that error are below), i.e. tonus's accuracy.\n";
  std::snprintf(line, sizeof line, "  %-10s %17s %17s %17s | %-31s | %-31s\n", "scene", "tonus mean / p99",
                "MuJoCo mean / p99", "matched mean / p99", "tonus/MuJoCo mean, p99", "tonus/matched mean, p99");
  out << line;
  for (const auto& spec : tonus::bench::benchmark_scenes()) {
    const auto* t = rep.figures("BM_Tonus/" + spec.name);
    const auto* d = rep.figures("BM_Mujoco/" + spec.name);
    const auto* x = rep.figures("BM_MujocoMatched/" + spec.name);
    if (t == nullptr && d == nullptr && x == nullptr) continue;
    const auto pair = [](const SummaryReporter::Figures* f) {
      char s[40];
      if (f == nullptr) return std::string("        -        ");
      std::snprintf(s, sizeof s, "%8.1f / %6.1f", get(f, "mean_us"), get(f, "p99_us"));
      return std::string(s);
    };
    std::snprintf(line, sizeof line, "  %-10s %17s %17s %17s | %s %s | %s %s\n", spec.name.c_str(), pair(t).c_str(),
                  pair(d).c_str(), pair(x).c_str(), ratio(get(t, "mean_us"), get(d, "mean_us"), kMeanGoal).c_str(),
                  ratio(get(t, "p99_us"), get(d, "p99_us"), kP99Goal).c_str(),
                  ratio(get(t, "mean_us"), get(x, "mean_us"), kMeanGoal).c_str(),
                  ratio(get(t, "p99_us"), get(x, "p99_us"), kP99Goal).c_str());
    out << line;
  }
}

void print_mujoco_solver(const SummaryReporter& rep, std::ostream& out) {
  if (!any_scene_ran(rep, {"BM_Mujoco/", "BM_MujocoMatched/"})) return;
  char line[512];
  out << "\nMuJoCo's solve (qvel err: the largest end-of-step qvel difference from a converged solve, m/s or rad/s)\n";
  std::snprintf(line, sizeof line, "  %-10s %-9s %9s %9s %9s %10s %11s %9s\n", "scene", "settings", "contacts",
                "iter mean", "iter p99", "tolerance", "qvel err", "overflow");
  out << line;
  for (const auto& spec : tonus::bench::benchmark_scenes()) {
    for (const auto& [label, family] :
         {std::pair{"default", "BM_Mujoco/"}, std::pair{"matched", "BM_MujocoMatched/"}}) {
      const auto* f = rep.figures(family + spec.name);
      if (f == nullptr) continue;
      std::snprintf(line, sizeof line, "  %-10s %-9s %9.1f %9.2f %9.0f %10.0e %11.2g %9.0f\n", spec.name.c_str(), label,
                    get(f, "contacts"), get(f, "iter_mean"), get(f, "iter_p99"), get(f, "tolerance"),
                    get(f, "qvel_err"), get(f, "contact_overflow"));
      out << line;
    }
  }
}

void print_solvers(const SummaryReporter& rep, std::ostream& out) {
  char line[512];
  if (!any_scene_ran(rep, {"BM_Tonus/"})) return print_mujoco_solver(rep, out);
  const auto model = tonus::bench::standing_humanoid();
  out << "\ntonus's contact solve (goal: residual <= " << kResidualGoal << " m/s every step; the model allows "
      << model->solver.iterations << " sweeps and stops at tolerance " << model->solver.tolerance << ")\n";
  std::snprintf(line, sizeof line, "  %-10s %9s %13s %13s %10s %12s %9s %9s %9s\n", "scene", "contacts", "residual p99",
                "residual max", "converged", "unconverged", "iter mean", "iter p99", "overflow");
  out << line;
  for (const auto& spec : tonus::bench::benchmark_scenes()) {
    const auto* t = rep.figures("BM_Tonus/" + spec.name);
    if (t == nullptr) continue;
    std::snprintf(line, sizeof line, "  %-10s %9.1f %13.3g %13.3g %9.2f%% %12.0f %9.1f %9.0f %9.0f\n",
                  spec.name.c_str(), get(t, "contacts"), get(t, "residual_p99"), get(t, "residual_max"),
                  100.0 * get(t, "converged_frac"), get(t, "unconverged"), get(t, "iter_mean"), get(t, "iter_p99"),
                  get(t, "contact_overflow"));
    out << line;
  }
  print_mujoco_solver(rep, out);
}

// Least squares of y = a + b x, with R^2.
struct Fit {
  double a = 0.0, b = 0.0, r2 = 0.0;
  bool ok = false;
};
Fit fit_line(const std::vector<std::pair<double, double>>& xy) {
  Fit f;
  if (xy.size() < 2) return f;
  const double n = static_cast<double>(xy.size());
  double sx = 0.0, sy = 0.0;
  for (const auto& [x, y] : xy) sx += x, sy += y;
  const double mx = sx / n, my = sy / n;
  double sxx = 0.0, sxy = 0.0, syy = 0.0;
  for (const auto& [x, y] : xy) {
    sxx += (x - mx) * (x - mx);
    sxy += (x - mx) * (y - my);
    syy += (y - my) * (y - my);
  }
  if (sxx <= 0.0) return f;
  f.b = sxy / sxx;
  f.a = my - f.b * mx;
  double ss_res = 0.0;
  for (const auto& [x, y] : xy) ss_res += (y - f.a - f.b * x) * (y - f.a - f.b * x);
  f.r2 = syy > 0.0 ? 1.0 - ss_res / syy : 1.0;
  f.ok = true;
  return f;
}

void print_scaling(const SummaryReporter& rep, std::ostream& out) {
  char line[256];
  std::vector<std::pair<double, double>> points, logs, marginal_logs;
  const auto* base = rep.figures("BM_TonusScaling/0");
  bool header = false;
  for (const int n : kScalingBoxes) {
    const auto* f = rep.figures("BM_TonusScaling/" + std::to_string(n));
    if (f == nullptr) continue;
    if (!header) {
      out << "\nscaling: tonus on a pile of N boxes (" << kScalingSteps << " steps each, after 1000 settling)\n";
      std::snprintf(line, sizeof line, "  %6s %9s %9s %9s %9s\n", "boxes", "contacts", "mean us", "p99 us", "overflow");
      out << line;
      header = true;
    }
    const double c = get(f, "contacts"), us = get(f, "mean_us");
    std::snprintf(line, sizeof line, "  %6d %9.1f %9.1f %9.1f %9.0f\n", n, c, us, get(f, "p99_us"),
                  get(f, "contact_overflow"));
    out << line;
    points.emplace_back(c, us);
    if (c > 0.0 && us > 0.0) logs.emplace_back(std::log(c), std::log(us));
    if (base != nullptr && n > 0) {
      const double dc = c - get(base, "contacts"), dus = us - get(base, "mean_us");
      if (dc > 0.0 && dus > 0.0) marginal_logs.emplace_back(std::log(dc), std::log(dus));
    }
  }
  const Fit lin = fit_line(points), lg = fit_line(logs), mg = fit_line(marginal_logs);
  if (lin.ok) {
    std::snprintf(line, sizeof line, "  least squares: us = %.2f + %.3f * contacts (R^2 = %.3f)\n", lin.a, lin.b,
                  lin.r2);
    out << line;
  }
  if (lg.ok) {
    std::snprintf(line, sizeof line, "  log-log slope of us against contacts: %.2f (1 = linear, 2 = quadratic)\n",
                  lg.b);
    out << line;
  }
  if (mg.ok) {
    std::snprintf(line, sizeof line,
                  "  the same for what the boxes add (us and contacts above the 0-box pile): %.2f (R^2 = %.3f)\n", mg.b,
                  mg.r2);
    out << line;
  }
  if (header && !lin.ok) out << "  (too few sizes ran for a fit)\n";
}

void print_summary(const SummaryReporter& rep, std::ostream& out) {
  print_times(rep, out);
  print_solvers(rep, out);
  const auto* dual = rep.figures("BM_DualTick");
  const auto* mj = rep.figures("BM_Mujoco/static");
  if (dual != nullptr) {
    out << "\ndual tick (two steps, static scene): " << get(dual, "time_us") << " us";
    if (get(mj, "mean_us") > 0.0) out << " = " << get(dual, "time_us") / get(mj, "mean_us") << " MuJoCo steps";
    out << "\n";
  }
  out << "memory: sizeof(Model) = " << sizeof(Model) << " B, sizeof(Data) = " << sizeof(Data) << " B\n";
  print_scaling(rep, out);
  if (!skipped().empty()) {
    out << "\nskipped:\n";
    for (const auto& [name, why] : skipped()) out << "  " << name << ": " << why << "\n";
  }
}

// Google Benchmark keeps every registered case for the life of the process;
// clang's analyser, not knowing that, takes each registration for a leak.
void register_benchmarks() {
#ifndef __clang_analyzer__
  for (const SceneSpec& spec : tonus::bench::benchmark_scenes()) {
    const std::string tonus = "BM_Tonus/" + spec.name;
    benchmark::RegisterBenchmark(tonus.c_str(), [spec, tonus](benchmark::State& st) {
      BM_Tonus(st, spec, tonus);
    })->Unit(benchmark::kMicrosecond);
    const std::string mujoco = "BM_Mujoco/" + spec.name;
    benchmark::RegisterBenchmark(mujoco.c_str(), [spec, mujoco](benchmark::State& st) {
      BM_Mujoco(st, spec, false, mujoco);
    })->Unit(benchmark::kMicrosecond);
    const std::string matched = "BM_MujocoMatched/" + spec.name;
    benchmark::RegisterBenchmark(matched.c_str(), [spec, matched](benchmark::State& st) {
      BM_Mujoco(st, spec, true, matched);
    })->Unit(benchmark::kMicrosecond);
  }
  benchmark::RegisterBenchmark("BM_DualTick", BM_DualTick)->Unit(benchmark::kMicrosecond);
  for (const int n : kScalingBoxes) {
    const SceneSpec spec = tonus::bench::pile_scene(n);
    const std::string name = "BM_TonusScaling/" + std::to_string(n);
    benchmark::RegisterBenchmark(name.c_str(), [spec, name](benchmark::State& st) { BM_Tonus(st, spec, name); })
        ->Iterations(kScalingSteps)
        ->Unit(benchmark::kMicrosecond);
  }
#endif
}

}  // namespace

int main(int argc, char** argv) {
  bool json = false;
  for (int i = 1; i < argc; ++i) json = json || std::string(argv[i]) == "--benchmark_format=json";
  register_benchmarks();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  SummaryReporter reporter(json);
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  print_summary(reporter, json ? std::cerr : std::cout);
  // A scene that does not fit the capacities is reported, not a failure (the
  // capacities are the physics core's choice); anything else that stopped a
  // case (divergence, MuJoCo refusing the export) fails the run.
  const std::string full(to_string(tonus::sim::ObjectError::full));
  for (const auto& [name, why] : skipped()) {
    if (why.find(full) == std::string::npos) return 1;
  }
  return 0;
}
