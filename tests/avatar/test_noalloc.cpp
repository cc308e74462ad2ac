// The controller allocates nothing after create(), gifts and stiffness changes included (counted).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "support/allocation_counter.hpp"
#include "tonus/host/avatar/controller.hpp"
#include "tonus/sim/humanoid.hpp"

using namespace tonus;
using namespace tonus::avatar;
using sim::Bone;
using std::size_t;

namespace {

struct Run {
  long allocations = 0;
  int ticks_with_events = 0;
  int rate_limited = 0;
  AvatarStats stats;
};

void set_quat(const sim::Model& m, ReferencePose& r, Bone b, const sim::Quat& q) {
  const auto a = static_cast<size_t>(m.bodies[sim::index(b)].qpos_adr);
  r.qpos[a] = q.w();
  r.qpos[a + 1] = q.x();
  r.qpos[a + 2] = q.y();
  r.qpos[a + 3] = q.z();
}

Run run(const sim::Model& m, const AvatarConfig& cfg, int ticks) {
  AvatarController::Created made = AvatarController::create(m, cfg);
  REQUIRE_MESSAGE(made, made.error);
  AvatarController& c = *made.controller;
  TickInput in;
  in.reference = rest_reference(m);
  in.reference.has_velocity = false;
  const auto elbow = static_cast<size_t>(m.bodies[sim::index(Bone::RightLowerArm)].qpos_adr);
  std::array<GiftId, 4> live{};
  Run r;
  REQUIRE(tonus::test::probe_allocation_counter() == 2);
  tonus::test::start_counting_allocations();
  for (int t = 0; t < ticks; ++t) {
    const double s = t * m.timestep_s;
    set_quat(m, in.reference, Bone::RightUpperArm,
             sim::Quat(Eigen::AngleAxisd(0.6 + 0.4 * std::sin(3.0 * s), sim::Vec3::UnitX())));
    set_quat(m, in.reference, Bone::LeftUpperArm, sim::Quat(Eigen::AngleAxisd(-0.8, sim::Vec3::UnitX())));
    in.reference.qpos[elbow] = 1.0 + 0.5 * std::sin(2.0 * s);
    in.reference.qpos[0] = t < ticks / 2 ? 0.0 : 1.0;  // one teleport: a jump
    const double level = 0.5 + 0.5 * std::sin(1.3 * s);
    in.stiffness = {level, 1.0 - level, (t / 400) % 2 == 0 ? 0.0 : 1.0, 0.5};
    TickInput used = in;
    if (t % 1000 == 999) used.reference.qpos[elbow] = std::nan("");  // a broken reference now and then
    if (t % 500 == 100) {
      ThrowBall b;
      b.target = (t / 500) % 2 == 0 ? Bone::Chest : Bone::Head;
      b.lifetime_s = 1.0;
      (void)c.throw_ball(b);
    }
    if (t % 700 == 50) {
      const auto k = static_cast<size_t>(t / 700) % live.size();
      (void)c.remove(live[k]);
      live[k] = c.drop_cube(DropCube{}).id;
    }
    if (t % 2500 == 2400) c.clear_gifts();
    const TickOutput& o = c.tick(used);
    r.ticks_with_events += o.nevents > 0 ? 1 : 0;
    r.rate_limited += (o.flags & kStiffnessRateLimited) != 0 ? 1 : 0;
  }
  r.allocations = tonus::test::stop_counting_allocations();
  r.stats = c.stats();
  return r;
}

}  // namespace

TEST_CASE("ticks, gifts and stiffness changes allocate nothing after create()") {
  const sim::BuildResult built = sim::build_humanoid(sim::HumanoidSpec{});
  REQUIRE(built);
  struct Variant {
    Feedforward feedforward;
    RootControl root;
    int ticks;
  };
  for (const Variant v : {Variant{Feedforward::simulation, RootControl::kinematic, 10000},
                          Variant{Feedforward::inverse_dynamics, RootControl::kinematic, 1000},
                          Variant{Feedforward::none, RootControl::free_servo, 1000}}) {
    AvatarConfig cfg;
    cfg.feedforward = v.feedforward;
    cfg.root = v.root;
    const Run r = run(*built.model, cfg, v.ticks);
    const std::string name(to_string(v.feedforward));
    CAPTURE(name);
    MESSAGE(name << ": " << r.allocations << " allocations in " << v.ticks << " ticks (" << r.stats.gifts_spawned
                 << " gifts, " << r.ticks_with_events << " ticks with contact events, " << r.stats.reference_jumps
                 << " jumps, " << r.stats.reference_invalid << " broken references)");
    CHECK(r.allocations == 0);
    CHECK(r.stats.ticks == static_cast<std::uint64_t>(v.ticks));
    CHECK(r.stats.gifts_spawned >= static_cast<std::uint64_t>(v.ticks / 500));
    CHECK(r.ticks_with_events > 20);  // the gifts touched the avatar
    CHECK(r.rate_limited > 100);
    CHECK(r.stats.reference_jumps >= 1);
    CHECK(r.stats.reference_invalid >= static_cast<std::uint64_t>(v.ticks / 1000));
  }
}
