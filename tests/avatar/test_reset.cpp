// B blow-up guard: reset to A within the tick, B's clock running on; a heavy gift in flight is no blow-up.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "avatar_fixtures.hpp"
#include "tonus/sim/step.hpp"

using namespace tonus;
using namespace tonus::avatar;
using namespace tonus::avatar::test;
using std::size_t;

namespace {

bool b_equals_a(const AvatarController& c) {
  const sim::Model& m = humanoid();
  for (size_t k = 0; k < static_cast<size_t>(m.nq); ++k) {
    if (c.sim_b().qpos[k] != c.sim_a().qpos[k] || c.output().qpos[k] != c.sim_a().qpos[k]) return false;
  }
  for (size_t k = 0; k < static_cast<size_t>(m.nv); ++k) {
    if (c.sim_b().qvel[k] != c.sim_a().qvel[k]) return false;
  }
  return true;
}

// Ticks until the first contact event with an impulse (or `limit`); true when no tick before it reset B.
bool fly_until_contact(AvatarController& c, const TickInput& in, int limit) {
  bool clean = true;
  for (int k = 0; k < limit; ++k) {
    const TickOutput& o = c.tick(in);
    for (int e = 0; e < o.nevents; ++e) {
      if (o.events[static_cast<size_t>(e)].impulse_ns > 0.0) return clean;
    }
    clean = clean && (o.flags & kResetB) == 0;
  }
  return false;
}

}  // namespace

TEST_CASE("a 1000 kg ball at 100 m/s flings B: reset to A's state within the tick, outputs finite") {
  AvatarController c = make_controller();
  TickInput in;
  in.reference = rest_reference(humanoid());
  for (int k = 0; k < 100; ++k) c.tick(in);
  ThrowBall b;
  b.mass_kg = 1000.0;  // the largest accepted
  b.speed_mps = 100.0;
  b.lifetime_s = 0.1;
  const SpawnResult r = c.throw_ball(b);
  REQUIRE(r.ok());
  // The flight is no blow-up (the ball's own 5 MJ are not B's).
  REQUIRE(fly_until_contact(c, in, 100));
  // The tick of the hit: B's joints were flung, and reset to A's state.
  CHECK((c.output().flags & kResetB) != 0);
  CHECK(b_equals_a(c));
  CHECK(all_finite(c.output()));
  CHECK(c.stats().resets_b == 1);
  for (int k = 0; k < 300; ++k) {
    const TickOutput& o = c.tick(in);
    REQUIRE(all_finite(o));
    if ((o.flags & kResetB) != 0) CHECK(b_equals_a(c));
  }
  MESSAGE("the absurd ball reset B on " << c.stats().resets_b << " ticks (its lifetime 0.1 s)");
  // B's clock ran on through the undone steps (else the lifetime would never end).
  CHECK(c.output().time_s == doctest::Approx(static_cast<double>(c.stats().ticks) * humanoid().timestep_s));
  // Once the ball is gone (lifetime), B runs on its own again and holds the pose.
  CHECK(c.gift_count() == 0);
  CHECK((c.output().flags & kResetB) == 0);
  double worst = 0.0;
  for (size_t i = 1; i < sim::kBoneCount; ++i) worst = std::max(worst, c.output().deviation_rad[i]);
  CHECK(worst < 0.01);
}

TEST_CASE("a broken B state (NaN velocity) is reset to A's within the tick") {
  AvatarController c = make_controller();
  TickInput in;
  in.reference = arms_lowered(0.5, 0.5);
  for (int k = 0; k < 100; ++k) c.tick(in);
  // Test-only: no public input can write B's state, so break it in place.
  auto& b = const_cast<sim::Data&>(c.sim_b());
  b.qvel[12] = std::numeric_limits<double>::quiet_NaN();
  const TickOutput& o = c.tick(in);
  CHECK((o.flags & kResetB) != 0);
  CHECK(c.stats().resets_b == 1);
  CHECK(b_equals_a(c));
  CHECK(all_finite(o));
  // And a huge but finite one, beyond the energy bound.
  b.qvel[20] = 500.0;
  CHECK((c.tick(in).flags & kResetB) != 0);
  CHECK(b_equals_a(c));
  CHECK(c.stats().resets_b == 2);
  for (int k = 0; k < 10; ++k) CHECK((c.tick(in).flags & kResetB) == 0);
}

TEST_CASE("a heavy gift in flight is not a blow-up of B") {
  // A 20 kg medicine ball at 8 m/s carries 640 J, above the 500 J margin on its own.
  AvatarController c = make_controller();
  TickInput in;
  in.reference = rest_reference(humanoid());
  for (int k = 0; k < 50; ++k) c.tick(in);
  ThrowBall b;
  b.mass_kg = 20.0;
  b.radius_m = 0.14;
  const SpawnResult r = c.throw_ball(b);
  REQUIRE(r.ok());
  CHECK(fly_until_contact(c, in, 400));
  CHECK(c.stats().resets_b == 0);
}
