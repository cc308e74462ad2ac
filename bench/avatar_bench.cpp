// One avatar tick against MuJoCo's mj_step on the same scene, in one run.
//
// The scene (dt = 1 ms): the default humanoid standing on the ground, its
// hips held where the reference puts them (kinematic root; the controller
// then keeps B's body off the ground, as MuJoCo's copy does), holding the
// paper's pose (right forearm forward, hand level, left arm down) at
// stiffness 1 in every group, a 1 kg cube resting on the right hand.
//   static: only that, settled for 1 s before timing.
//   lively: the same, plus a 0.45 kg ball (radius 0.11 m) thrown at the chest
//           at 8 m/s every 0.5 s of simulated time, each removed 1 s after it
//           was thrown: contacts come and go while timing.
//
// BM_AvatarTick: one AvatarController::tick (reference checks, stiffness ->
// gains, simulation A: stiff drives, kinematic root, contact-free; its
// applied torque bounded as feedforward; simulation B: the weak drives, the
// gifts and their contacts; the outputs and contact events). The feedforward
// variants (simulation, inverse dynamics, none) on the static scene too.
//
// BM_MujocoStep: one mj_step of MuJoCo 2.2.2 on the MJCF export of the same
// scene. MuJoCo simulates ONE system, the avatar's simulation B: the hips
// welded where B's kinematic root holds them (the reference is still, so a
// kinematic root is a fixed one); B's collision switches (with a kinematic
// root its body does not touch the ground, the gifts do); B's weak drive
// gains as joint springs toward the held pose (stiffness per joint, damping
// per dof, taken from the controller after settling; a ball joint's per-axis
// stiffness averaged); A's feedforward as a constant applied generalized
// force; the ground, the cube and, for the lively scene, three free ball
// bodies that take turns: one is launched (qpos/qvel written) with exactly
// the state throw_ball gives, and parked 1 s later (moved far away, its
// collisions switched off). MuJoCo's soft friction lets the cube creep off
// the hand over a long run, so MuJoCo's body and cube are put back as they
// settled every 5 s.
// The tonus tick runs TWO simulations (A and B) plus the mapping, so a
// ratio of 1 means the whole tick costs one MuJoCo step.
//
// Only the tick or the step is timed (manual time, one steady_clock sample
// per iteration, which also gives the percentiles); throwing, launching and
// parking balls happen between samples in both.
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <unistd.h>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "forwarding_reporter.hpp"
#include "tonus/host/avatar/controller.hpp"
#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/mjcf.hpp"
#include "tonus/sim/objects.hpp"
#include "tonus/sim/step.hpp"

namespace {

using namespace tonus;
using avatar::Feedforward;
using sim::Bone;
using sim::Vec3;
using std::size_t;

constexpr double kSettleS = 1.0;        // after the cube is dropped, before timing
constexpr double kThrowEveryS = 0.5;    // lively: a ball this often ...
constexpr double kBallLifetimeS = 1.0;  // ... removed this long after its throw
constexpr double kReseatS = 5.0;        // MuJoCo's cube put back this often (see MujocoScene)
constexpr int kBalls = 3;               // MuJoCo's ball bodies: enough for every ball alive at once

const sim::Model& humanoid() {
  static const std::unique_ptr<sim::Model> model = [] {
    sim::BuildResult r = sim::build_humanoid(sim::HumanoidSpec{});
    if (!r) {
      std::fprintf(stderr, "tonus-bench-avatar: %s\n", r.error.c_str());
      std::exit(1);
    }
    return std::move(r.model);
  }();
  return *model;
}

int ticks(double s) { return static_cast<int>(std::lround(s / humanoid().timestep_s)); }

// The paper's held pose: the right upper arm lowered 1 rad from the T-pose,
// the elbow at 90 degrees (forearm forward), the wrist's twist levelling the
// hand; the left arm lowered 1.3 rad.
avatar::ReferencePose held_pose(const sim::Model& m) {
  avatar::ReferencePose r = avatar::rest_reference(m);
  const auto ball = [&](Bone b, const sim::Quat& q) {
    const auto a = static_cast<size_t>(m.bodies[sim::index(b)].qpos_adr);
    r.qpos[a] = q.w();
    r.qpos[a + 1] = q.x();
    r.qpos[a + 2] = q.y();
    r.qpos[a + 3] = q.z();
  };
  ball(Bone::RightUpperArm, sim::Quat(Eigen::AngleAxisd(1.0, Vec3::UnitX())));
  r.qpos[static_cast<size_t>(m.bodies[sim::index(Bone::RightLowerArm)].qpos_adr)] = M_PI / 2.0;
  ball(Bone::RightHand, sim::Quat(Eigen::AngleAxisd(1.0, Vec3::UnitY())));
  ball(Bone::LeftUpperArm, sim::Quat(Eigen::AngleAxisd(-1.3, Vec3::UnitX())));
  return r;
}

avatar::ThrowBall ball_spec() {
  avatar::ThrowBall b;
  b.target = Bone::Chest;
  b.mass_kg = 0.45;
  b.radius_m = 0.11;
  b.speed_mps = 8.0;
  b.lifetime_s = kBallLifetimeS;
  return b;
}

// Per-iteration times, preallocated so the loop does not allocate.
class Samples {
 public:
  explicit Samples(benchmark::IterationCount n) { us_.reserve(static_cast<size_t>(n)); }
  void add(std::chrono::steady_clock::duration d) {
    us_.push_back(std::chrono::duration<double, std::micro>(d).count());
  }
  void report(benchmark::State& state) {
    if (us_.empty()) return;
    std::sort(us_.begin(), us_.end());
    const auto at = [&](double q) {
      const auto k = static_cast<size_t>(std::ceil(q * static_cast<double>(us_.size()))) - 1;
      return us_[std::min(k, us_.size() - 1)];
    };
    state.counters["p50_us"] = at(0.50);
    state.counters["p99_us"] = at(0.99);
    state.counters["max_us"] = us_.back();
  }

 private:
  std::vector<double> us_;
};

// Contacts per step, averaged over the timed iterations, and the largest count.
struct ContactCount {
  double sum = 0.0;
  int max = 0;
  std::int64_t n = 0;
  std::int64_t ball_ticks = 0;  // steps with a ball touching the body
  void add(int ncon, bool ball_on_body) {
    sum += ncon;
    max = std::max(max, ncon);
    ++n;
    ball_ticks += ball_on_body ? 1 : 0;
  }
  void report(benchmark::State& state, bool lively) const {
    if (n == 0) return;
    state.counters["contacts"] = sum / static_cast<double>(n);
    state.counters["contacts_max"] = max;
    if (lively) state.counters["ball_on_body_pct"] = 100.0 * static_cast<double>(ball_ticks) / static_cast<double>(n);
  }
};

// ---------------------------------------------------------------- tonus --

struct AvatarScene {
  std::optional<avatar::AvatarController> c;
  avatar::TickInput in;
  avatar::GiftId cube;
  bool lively = false;
  std::int64_t tick = 0;  // ticks since the throws began (lively)
  std::string error;

  // A ball every kThrowEveryS (lively); not timed.
  void before_tick() {
    if (lively && tick % ticks(kThrowEveryS) == 0) c->throw_ball(ball_spec());
    ++tick;
  }
  [[nodiscard]] bool ball_on_body(const avatar::TickOutput& o) const {
    for (int e = 0; e < o.nevents; ++e) {
      if (!(o.events[static_cast<size_t>(e)].gift == cube)) return true;
    }
    return false;
  }
  [[nodiscard]] bool cube_on_hand() const {
    const sim::Object* o = sim::find_object(c->sim_b(), {cube.slot, cube.generation});
    const sim::Model& m = humanoid();
    const Vec3 hand =
        c->sim_b().xgeom[static_cast<size_t>(m.first_geom(static_cast<int>(sim::index(Bone::RightHand))))].pos;
    return o != nullptr && o->pos.z() > hand.z() && (o->pos - hand).head<2>().norm() < 0.1;
  }
};

std::unique_ptr<AvatarScene> make_avatar_scene(Feedforward ff, bool lively) {
  const sim::Model& m = humanoid();
  auto s = std::make_unique<AvatarScene>();
  avatar::AvatarConfig cfg;
  cfg.feedforward = ff;
  auto made = avatar::AvatarController::create(m, cfg);
  if (!made) {
    s->error = made.error;
    return s;
  }
  s->c.emplace(std::move(*made.controller));
  s->in.reference = held_pose(m);
  s->in.stiffness.fill(1.0);
  s->c->set_stiffness_now(s->in.stiffness);
  s->c->tick(s->in);  // A and B resynced to the pose
  avatar::DropCube cube;
  cube.target = Bone::RightHand;
  cube.height_m = 0.005;
  const avatar::SpawnResult r = s->c->drop_cube(cube);
  if (!r.ok()) {
    s->error = "the cube was refused: " + std::string(avatar::to_string(r.error));
    return s;
  }
  s->cube = r.id;
  for (int k = 0; k < ticks(kSettleS); ++k) s->c->tick(s->in);
  s->lively = lively;
  if (lively) {  // the throws under way (two balls alive) before timing
    for (int k = 0; k < ticks(kBallLifetimeS); ++k) {
      s->before_tick();
      s->c->tick(s->in);
    }
  }
  return s;
}

// Scenes are built once and kept across Google Benchmark's calls, so their
// settling happens once and the lively schedule carries on.
AvatarScene& avatar_scene(Feedforward ff, bool lively) {
  humanoid();  // built first, so it outlives the scenes
  static std::map<std::pair<int, bool>, std::unique_ptr<AvatarScene>> scenes;
  auto& s = scenes[{static_cast<int>(ff), lively}];
  if (!s) s = make_avatar_scene(ff, lively);
  return *s;
}

void BM_AvatarTick(benchmark::State& state, Feedforward ff, bool lively) {
  AvatarScene& s = avatar_scene(ff, lively);
  if (!s.error.empty()) {
    state.SkipWithError(s.error.c_str());
    return;
  }
  Samples samples(state.max_iterations);
  ContactCount contacts;
  const avatar::AvatarStats before = s.c->stats();
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    s.before_tick();
    const auto t0 = std::chrono::steady_clock::now();
    const avatar::TickOutput& o = s.c->tick(s.in);
    const auto t1 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(o.qpos.data());
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
    samples.add(t1 - t0);
    contacts.add(s.c->sim_b().ncon, s.ball_on_body(o));
  }
  samples.report(state);
  contacts.report(state, lively);
  const avatar::AvatarStats& after = s.c->stats();
  state.counters["cube_on_hand"] = s.cube_on_hand() ? 1 : 0;
  state.counters["resets"] = static_cast<double>(after.resets_a + after.resets_b - before.resets_a - before.resets_b);
  if (lively) state.counters["throws"] = static_cast<double>(after.gifts_spawned - before.gifts_spawned);
}
BENCHMARK_CAPTURE(BM_AvatarTick, static, Feedforward::simulation, false)
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_AvatarTick, lively, Feedforward::simulation, true)->UseManualTime()->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_AvatarTick, static_ff_inverse_dynamics, Feedforward::inverse_dynamics, false)
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_AvatarTick, static_ff_none, Feedforward::none, false)
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// --------------------------------------------------------------- MuJoCo --

// Entry i of a MuJoCo array of 3-vectors.
Vec3 mj_vec3(const mjtNum* a, int i) {
  const mjtNum* p = a + 3 * static_cast<std::ptrdiff_t>(i);
  return {p[0], p[1], p[2]};
}

struct MjBall {
  int body = -1, geom = -1, qadr = -1, dadr = -1;
  int contype = 0, conaffinity = 0;
};

struct MujocoScene {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  bool lively = false;
  std::int64_t tick = 0;
  int throws = 0;
  int cube_body = -1, hand_geom = -1;
  Vec3 hand_b = Vec3::Zero();  // B's hand when exported: how far MuJoCo's drifts from it
  std::array<MjBall, kBalls> balls{};
  std::array<double, 3> launch_pos{}, launch_vel{};
  // MuJoCo's soft friction lets the cube creep down the hand (about 1 mm/s
  // here; tonus's stays put), so the body and the cube are put back as they
  // settled every kReseatS, between samples.
  std::vector<mjtNum> settled_qpos, settled_qvel, settled_warmstart;
  int reseats = 0;
  std::string error;

  MujocoScene() = default;
  MujocoScene(const MujocoScene&) = delete;
  MujocoScene& operator=(const MujocoScene&) = delete;
  ~MujocoScene() {
    if (d != nullptr) mj_deleteData(d);
    if (m != nullptr) mj_deleteModel(m);
  }

  void park(MjBall& b) {
    m->geom_contype[b.geom] = 0;
    m->geom_conaffinity[b.geom] = 0;
    const double x = 100.0 + 10.0 * static_cast<double>(&b - balls.data());
    const std::array<double, 7> q{x, 0.0, 10.0, 1.0, 0.0, 0.0, 0.0};
    std::copy(q.begin(), q.end(), d->qpos + b.qadr);
    std::fill_n(d->qvel + b.dadr, 6, 0.0);
  }
  void launch(MjBall& b) {
    m->geom_contype[b.geom] = b.contype;
    m->geom_conaffinity[b.geom] = b.conaffinity;
    std::copy(launch_pos.begin(), launch_pos.end(), d->qpos + b.qadr);
    const std::array<double, 4> q{1.0, 0.0, 0.0, 0.0};
    std::copy(q.begin(), q.end(), d->qpos + b.qadr + 3);
    std::copy(launch_vel.begin(), launch_vel.end(), d->qvel + b.dadr);
    std::fill_n(d->qvel + b.dadr + 3, 3, 0.0);
  }
  void snapshot() {
    settled_qpos.assign(d->qpos, d->qpos + m->nq);
    settled_qvel.assign(d->qvel, d->qvel + m->nv);
    settled_warmstart.assign(d->qacc_warmstart, d->qacc_warmstart + m->nv);
  }
  void reseat() {  // the balls stay as they are
    std::array<mjtNum, 13 * static_cast<size_t>(kBalls)> keep{};
    for (size_t k = 0; lively && k < balls.size(); ++k) {
      std::copy_n(d->qpos + balls[k].qadr, 7, keep.begin() + static_cast<std::ptrdiff_t>(13 * k));
      std::copy_n(d->qvel + balls[k].dadr, 6, keep.begin() + static_cast<std::ptrdiff_t>(13 * k + 7));
    }
    std::copy(settled_qpos.begin(), settled_qpos.end(), d->qpos);
    std::copy(settled_qvel.begin(), settled_qvel.end(), d->qvel);
    std::copy(settled_warmstart.begin(), settled_warmstart.end(), d->qacc_warmstart);
    for (size_t k = 0; lively && k < balls.size(); ++k) {
      std::copy_n(keep.begin() + static_cast<std::ptrdiff_t>(13 * k), 7, d->qpos + balls[k].qadr);
      std::copy_n(keep.begin() + static_cast<std::ptrdiff_t>(13 * k + 7), 6, d->qvel + balls[k].dadr);
    }
    ++reseats;
  }
  // The same schedule as the avatar's: a ball every kThrowEveryS, parked
  // kBallLifetimeS after it was thrown; the reseat; not timed.
  void before_step() {
    if (tick > 0 && tick % ticks(kReseatS) == 0) reseat();
    if (lively && tick % ticks(kThrowEveryS) == 0) {
      const int lifetime_throws = static_cast<int>(std::lround(kBallLifetimeS / kThrowEveryS));
      if (throws >= lifetime_throws) park(balls[static_cast<size_t>((throws - lifetime_throws) % kBalls)]);
      launch(balls[static_cast<size_t>(throws % kBalls)]);
      ++throws;
    }
    ++tick;
  }
  [[nodiscard]] bool is_ball(int body) const {
    return std::any_of(balls.begin(), balls.end(), [&](const MjBall& b) { return b.body == body; });
  }
  [[nodiscard]] bool ball_on_body() const {
    for (int i = 0; i < d->ncon; ++i) {
      const int b1 = m->geom_bodyid[d->contact[i].geom1], b2 = m->geom_bodyid[d->contact[i].geom2];
      const auto humanoid_body = [&](int b) { return b > 0 && b != cube_body && !is_ball(b); };
      if ((is_ball(b1) && humanoid_body(b2)) || (is_ball(b2) && humanoid_body(b1))) return true;
    }
    return false;
  }
  [[nodiscard]] bool cube_on_hand() const {
    const Vec3 c = mj_vec3(d->xpos, cube_body), h = mj_vec3(d->geom_xpos, hand_geom);
    return c.z() > h.z() && (c - h).head<2>().norm() < 0.1;
  }
  [[nodiscard]] double hand_drift_m() const { return (mj_vec3(d->geom_xpos, hand_geom) - hand_b).norm(); }
};

std::string num(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// The root welded where B's kinematic root is: its free joint dropped and its
// body placed at the root's pose.
bool weld_root(std::string& xml, const sim::Model& m, const std::array<double, sim::kMaxQpos>& qpos) {
  const std::string name(m.bodies[0].name_view());
  const std::string joint = "<joint name=\"" + name + "\" type=\"free\"";
  const size_t j = xml.find(joint);
  const std::string body = "<body name=\"" + name + "\" ";
  const size_t b = xml.find(body);
  if (j == std::string::npos || b == std::string::npos || b > j) return false;
  const size_t line = xml.rfind('\n', j), end = xml.find('\n', j);
  xml.erase(line, end - line);
  const size_t close = xml.find('>', b);
  xml.replace(b, close - b,
              body + "pos=\"" + num(qpos[0]) + " " + num(qpos[1]) + " " + num(qpos[2]) + "\" quat=\"" + num(qpos[3]) +
                  " " + num(qpos[4]) + " " + num(qpos[5]) + " " + num(qpos[6]) + "\"");
  return true;
}

std::unique_ptr<MujocoScene> make_mujoco_scene(bool lively) {
  auto s = std::make_unique<MujocoScene>();
  s->lively = lively;
  const sim::Model& m = humanoid();
  // B's state, gains and feedforward after settling (a static avatar scene of its own).
  const std::unique_ptr<AvatarScene> src = make_avatar_scene(Feedforward::simulation, false);
  if (!src->error.empty()) {
    s->error = src->error;
    return s;
  }
  const avatar::AvatarController& c = *src->c;
  const sim::Data& b = c.sim_b();

  // The objects to export: the cube as B holds it, and parked balls.
  const std::unique_ptr<sim::Data> objects = sim::make_data(m);
  const sim::Object* cube = sim::find_object(b, {src->cube.slot, src->cube.generation});
  if (cube == nullptr) {
    s->error = "the cube is gone";
    return s;
  }
  sim::ObjectSpec spec;
  spec.shape = cube->shape;
  spec.mass_kg = cube->mass_kg;
  spec.material = cube->material;
  spec.pos = cube->pos;
  spec.quat = cube->quat;
  spec.lin_vel = cube->lin_vel;
  spec.ang_vel = cube->ang_vel;
  const sim::AddObjectResult cube_added = sim::add_object(*objects, spec);
  std::array<sim::ObjectHandle, kBalls> ball_handles{};
  const avatar::ThrowBall ball = ball_spec();
  for (size_t k = 0; lively && k < ball_handles.size(); ++k) {
    sim::ObjectSpec o;
    o.shape = sim::Shape::sphere(ball.radius_m);
    o.mass_kg = ball.mass_kg;
    o.material = {ball.friction, ball.restitution};
    o.pos = Vec3(100.0 + 10.0 * static_cast<double>(k), 0.0, 10.0);
    const sim::AddObjectResult r = sim::add_object(*objects, o);
    if (r.error != sim::ObjectError::none) {
      s->error = "a ball was refused";
      return s;
    }
    ball_handles[k] = r.handle;
  }
  if (cube_added.error != sim::ObjectError::none) {
    s->error = "the cube was refused";
    return s;
  }
  // Where throw_ball launches from, and how fast (AvatarController::throw_ball's flight).
  {
    const Vec3 target = b.xgeom[static_cast<size_t>(m.first_geom(static_cast<int>(sim::index(Bone::Chest))))].pos;
    const Vec3 dir = -b.xbody[0].rot.col(0).normalized();
    const double t = ball.distance_m / ball.speed_mps;
    const Vec3 g = m.features.gravity ? m.gravity : Vec3::Zero();
    const Vec3 p = target - dir * ball.distance_m, v = dir * ball.speed_mps - 0.5 * g * t;
    s->launch_pos = {p.x(), p.y(), p.z()};
    s->launch_vel = {v.x(), v.y(), v.z()};
  }

  sim::MjcfOptions opt;
  opt.drives_as_springs = true;
  opt.objects_from = objects.get();
  std::string xml = sim::to_mjcf(m, opt);
  if (!weld_root(xml, m, b.qpos)) {
    s->error = "the export has no free root to weld";
    return s;
  }
  char path[] = "/tmp/tonus-bench-avatar-XXXXXX.xml";
  const int fd = mkstemps(path, 4);
  if (fd < 0) {
    s->error = "no temporary file";
    return s;
  }
  close(fd);
  std::ofstream(path) << xml;
  char err[1024] = {0};
  s->m = mj_loadXML(path, nullptr, err, sizeof err);
  std::remove(path);
  if (s->m == nullptr) {
    s->error = err;
    return s;
  }
  s->d = mj_makeData(s->m);
  mjModel* mm = s->m;
  mjData* md = s->d;

  // B's collision switches (the export has the Model's): with a kinematic root
  // B's body does not touch the ground, the gifts do. The ground keeps its
  // type (objects have it in their affinity) and loses its affinity (bodies' type).
  const sim::CollisionSwitches& sw = b.collisions;
  if (!sw.objects) {
    s->error = "B's objects do not touch the body: not mirrored here";
    return s;
  }
  if (!sw.contacts) mm->opt.disableflags |= mjDSBL_CONTACT;
  if (const int ground = mj_name2id(mm, mjOBJ_GEOM, "ground"); ground >= 0) {
    if (!sw.ground) mm->geom_contype[ground] = 0;
    if (!sw.ground || !sw.body_ground) mm->geom_conaffinity[ground] = 0;
  }

  // Joints by name: B's state, its drives as springs toward the pose, A's feedforward.
  const avatar::TickOutput& out = c.output();
  for (int i = 1; i < m.nbody; ++i) {
    const sim::Body& body = m.bodies[static_cast<size_t>(i)];
    if (body.joint != sim::JointType::ball && body.joint != sim::JointType::hinge) continue;
    const int jid = mj_name2id(mm, mjOBJ_JOINT, std::string(body.name_view()).c_str());
    if (jid < 0) {
      s->error = "MuJoCo has no joint " + std::string(body.name_view());
      return s;
    }
    const int nq = body.joint == sim::JointType::ball ? 4 : 1, nv = body.joint == sim::JointType::ball ? 3 : 1;
    const auto qa = static_cast<size_t>(body.qpos_adr), da = static_cast<size_t>(body.dof_adr);
    double kp = 0.0;
    for (int k = 0; k < nq; ++k) {
      md->qpos[mm->jnt_qposadr[jid] + k] = b.qpos[qa + static_cast<size_t>(k)];
      mm->qpos_spring[mm->jnt_qposadr[jid] + k] = out.reference_qpos[qa + static_cast<size_t>(k)];
    }
    for (int k = 0; k < nv; ++k) {
      const size_t dof = da + static_cast<size_t>(k);
      const int mdof = mm->jnt_dofadr[jid] + k;
      md->qvel[mdof] = b.qvel[dof];
      mm->dof_damping[mdof] = c.mapper().kd(dof);
      md->qfrc_applied[mdof] = out.tau_ff[dof];
      kp += c.mapper().kp(dof) / nv;
    }
    mm->jnt_stiffness[jid] = kp;
  }
  const auto free_body = [&](sim::ObjectHandle h, MjBall& mb) {
    const std::string name = "object" + std::to_string(h.slot);
    const int jid = mj_name2id(mm, mjOBJ_JOINT, name.c_str());
    mb.body = mj_name2id(mm, mjOBJ_BODY, name.c_str());
    if (jid < 0 || mb.body < 0) return false;
    mb.geom = mm->body_geomadr[mb.body];
    mb.qadr = mm->jnt_qposadr[jid];
    mb.dadr = mm->jnt_dofadr[jid];
    mb.contype = mm->geom_contype[mb.geom];
    mb.conaffinity = mm->geom_conaffinity[mb.geom];
    return true;
  };
  MjBall cube_body;
  if (!free_body(cube_added.handle, cube_body)) {
    s->error = "MuJoCo has no cube";
    return s;
  }
  s->cube_body = cube_body.body;
  for (size_t k = 0; lively && k < s->balls.size(); ++k) {
    if (!free_body(ball_handles[k], s->balls[k])) {
      s->error = "MuJoCo has no ball";
      return s;
    }
    s->park(s->balls[k]);
  }
  s->hand_geom = mm->body_geomadr[mj_name2id(mm, mjOBJ_BODY,
                                             std::string(m.bodies[sim::index(Bone::RightHand)].name_view()).c_str())];
  mj_forward(mm, md);
  // The same configuration in both: B's hand where MuJoCo puts it.
  const Vec3 hand_b = b.xgeom[static_cast<size_t>(m.first_geom(static_cast<int>(sim::index(Bone::RightHand))))].pos;
  const Vec3 hand_mj = mj_vec3(md->geom_xpos, s->hand_geom);
  if ((hand_b - hand_mj).norm() > 1e-6) {
    s->error = "MuJoCo's hand is " + num((hand_b - hand_mj).norm()) + " m from B's";
    return s;
  }
  s->hand_b = hand_b;
  for (int k = 0; k < ticks(kSettleS); ++k) mj_step(mm, md);
  s->snapshot();
  if (lively) {
    for (int k = 0; k < ticks(kBallLifetimeS); ++k) {
      s->before_step();
      mj_step(mm, md);
    }
  }
  return s;
}

MujocoScene& mujoco_scene(bool lively) {
  static std::map<bool, std::unique_ptr<MujocoScene>> scenes;
  auto& s = scenes[lively];
  if (!s) s = make_mujoco_scene(lively);
  return *s;
}

void BM_MujocoStep(benchmark::State& state, bool lively) {
  MujocoScene& s = mujoco_scene(lively);
  if (!s.error.empty()) {
    state.SkipWithError(s.error.c_str());
    return;
  }
  Samples samples(state.max_iterations);
  ContactCount contacts;
  const int throws_before = s.throws, reseats_before = s.reseats;
  for (auto _ : state) {  // NOLINT(clang-analyzer-deadcode.DeadStores): Google Benchmark's loop idiom
    s.before_step();
    const auto t0 = std::chrono::steady_clock::now();
    mj_step(s.m, s.d);
    const auto t1 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(s.d->qpos);
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
    samples.add(t1 - t0);
    contacts.add(s.d->ncon, s.ball_on_body());
  }
  samples.report(state);
  contacts.report(state, lively);
  state.counters["cube_on_hand"] = s.cube_on_hand() ? 1 : 0;
  state.counters["hand_drift_mm"] = 1e3 * s.hand_drift_m();  // from where B holds it
  state.counters["reseats"] = s.reseats - reseats_before;
  if (lively) state.counters["throws"] = s.throws - throws_before;
}
BENCHMARK_CAPTURE(BM_MujocoStep, static, false)->UseManualTime()->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_MujocoStep, lively, true)->UseManualTime()->Unit(benchmark::kMicrosecond);

// ------------------------------------------------------------ reporting --

// Forwards to the reporter the flags ask for and keeps each case's mean time
// and 99th percentile (over repetitions when there are several, else the run).
class RatioReporter : public tonus::bench::ForwardingReporter {
 public:
  using ForwardingReporter::ForwardingReporter;
  struct Figures {
    double mean_us = 0.0, p99_us = 0.0, max_us = 0.0;
    bool valid = false;
  };
  [[nodiscard]] Figures figures(const std::string& name) const {
    const auto it = figures_.find(name);
    return it == figures_.end() ? Figures{} : it->second;
  }

 protected:
  void keep(const Run& r) override {
    const std::string& name = r.run_name.function_name;
    const auto counter = [&](const char* k) {
      const auto it = r.counters.find(k);
      return it == r.counters.end() ? 0.0 : static_cast<double>(it->second);
    };
    const Figures f{r.GetAdjustedRealTime() * unit_seconds(r.time_unit) * 1e6, counter("p99_us"), counter("max_us"),
                    true};
    const bool mean = r.run_type == Run::RT_Aggregate && r.aggregate_name == "mean";
    const bool first = r.run_type == Run::RT_Iteration && r.repetition_index <= 0 && !figures_[name].valid;
    if (mean || first) figures_[name] = f;  // the mean over repetitions replaces the first run
  }

 private:
  std::map<std::string, Figures> figures_;
};

void print_ratios(const RatioReporter& rep, std::ostream& out) {
  char line[256];
  out << "\navatar tick / MuJoCo step, same scene (goal: at most 1.0; the tick runs simulations A and B, MuJoCo "
         "one):\n";
  for (const char* scene : {"static", "lively"}) {
    const auto t = rep.figures(std::string("BM_AvatarTick/") + scene);
    const auto mj = rep.figures(std::string("BM_MujocoStep/") + scene);
    if (!t.valid || !mj.valid || mj.mean_us <= 0.0 || mj.p99_us <= 0.0) continue;
    std::snprintf(line, sizeof line, "  %-7s mean %7.1f us / %7.1f us = %5.2f   p99 %7.1f us / %7.1f us = %5.2f\n",
                  scene, t.mean_us, mj.mean_us, t.mean_us / mj.mean_us, t.p99_us, mj.p99_us, t.p99_us / mj.p99_us);
    out << line;
  }
  const auto mj = rep.figures("BM_MujocoStep/static");
  bool header = false;
  for (const auto& [variant, name] : {std::pair{"simulation", "BM_AvatarTick/static"},
                                      std::pair{"inverse_dynamics", "BM_AvatarTick/static_ff_inverse_dynamics"},
                                      std::pair{"none", "BM_AvatarTick/static_ff_none"}}) {
    const auto t = rep.figures(name);
    if (!t.valid) continue;
    if (!header) out << "feedforward variants, static scene, per tick:\n";
    header = true;
    std::snprintf(line, sizeof line, "  %-17s mean %7.1f us   p99 %7.1f us", variant, t.mean_us, t.p99_us);
    out << line;
    if (mj.valid && mj.mean_us > 0.0) {
      std::snprintf(line, sizeof line, "   = %5.2f MuJoCo steps", t.mean_us / mj.mean_us);
      out << line;
    }
    out << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  bool json = false;
  for (int i = 1; i < argc; ++i) json = json || std::string(argv[i]) == "--benchmark_format=json";
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter(json);
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  print_ratios(reporter, json ? std::cerr : std::cout);
  return 0;
}
