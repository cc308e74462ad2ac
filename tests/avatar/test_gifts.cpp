// Gifts: arrival times and impulses against closed forms, lifetimes, capacity, stale ids, clearing.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "avatar_fixtures.hpp"
#include "tonus/sim/objects.hpp"

using namespace tonus;
using namespace tonus::avatar;
using namespace tonus::avatar::test;
using sim::Bone;
using std::size_t;

namespace {

TickInput rest_input() {
  TickInput in;
  in.reference = rest_reference(humanoid());
  return in;
}

// A settled controller holding the rest pose.
AvatarController settled(const TickInput& in, const std::array<double, kGroupCount>& s = {0.5, 0.5, 0.5, 0.5}) {
  AvatarController c = make_controller();
  c.set_stiffness_now(s);
  for (int k = 0; k < 100; ++k) c.tick(in);
  return c;
}

// Normal impulse on the bones from one gift this tick, as a vector on the bones, and its scalar sum.
struct Hit {
  sim::Vec3 on_bones = sim::Vec3::Zero();
  double scalar = 0.0;
  int events = 0;
  Bone first = Bone::Hips;
};
Hit hit_by(const TickOutput& o, GiftId id) {
  Hit h;
  for (int e = 0; e < o.nevents; ++e) {
    const ContactEvent& ev = o.events[static_cast<size_t>(e)];
    if (!(ev.gift == id)) continue;
    if (h.events++ == 0) h.first = ev.bone;
    h.on_bones += ev.impulse_ns * ev.normal;
    h.scalar += ev.impulse_ns;
  }
  return h;
}

double shape_radius(Bone b) {
  const sim::Model& m = humanoid();
  const int g = m.first_geom(static_cast<int>(sim::index(b)));
  return g >= 0 ? m.geoms[static_cast<size_t>(g)].shape.radius_m : 0.0;
}

}  // namespace

TEST_CASE("a ball thrown at the chest from 1.5 m at 8 m/s hits it on time, and its momentum change is the impulse") {
  const TickInput in = rest_input();
  AvatarController c = settled(in);
  const ThrowBall spec;  // the defaults: 0.45 kg, r 0.11 m, 8 m/s from 1.5 m, at the chest
  const SpawnResult r = c.throw_ball(spec);
  REQUIRE(r.ok());
  CHECK(c.gift_count() == 1);
  const double t0 = c.sim_b().time_s;
  const sim::Object& ball = c.sim_b().objects[static_cast<size_t>(r.id.slot)];
  CHECK(ball.generation == r.id.generation);

  // Closed form: the horizontal speed is 8 m/s and the surfaces meet when the
  // centres are r_ball + r_chest apart (the chest capsule lies across the ball's path).
  const double expected = (spec.distance_m - spec.radius_m - shape_radius(Bone::Chest)) / spec.speed_mps;
  double t_hit = -1.0;
  sim::Vec3 v_before = ball.lin_vel;
  sim::Vec3 on_bones = sim::Vec3::Zero();
  double scalar = 0.0;
  int ticks_in_hit = 0, quiet = 0;
  Bone first = Bone::Hips;
  for (int k = 0; k < 1000 && quiet < 20; ++k) {
    const sim::Vec3 v_prev = ball.lin_vel;
    const TickOutput& o = c.tick(in);
    REQUIRE(all_finite(o));
    const Hit h = hit_by(o, r.id);
    if (t_hit < 0.0 && h.scalar > 0.0) {
      t_hit = o.time_s - t0;
      v_before = v_prev;
      first = h.first;
    }
    if (t_hit < 0.0) continue;
    CHECK(h.scalar >= 0.0);
    on_bones += h.on_bones;
    scalar += h.scalar;
    ++ticks_in_hit;
    quiet = h.events == 0 ? quiet + 1 : 0;
  }
  REQUIRE(t_hit > 0.0);
  // Momentum balance of the ball over the hit: m dv = -(impulse on the bones) + m g T (friction aside).
  const double m = spec.mass_kg;
  const sim::Vec3 dp = m * (ball.lin_vel - v_before) - m * humanoid().gravity * (ticks_in_hit * humanoid().timestep_s);
  MESSAGE("ball: first impulse on " << sim::name(first) << " after " << t_hit * 1e3 << " ms (closed form "
                                    << expected * 1e3 << " ms, centre to centre " << 1.5 / 8 * 1e3 << " ms); impulse "
                                    << scalar << " N*s, ball's momentum change " << dp.transpose() << " N*s");
  CHECK((first == Bone::Chest || first == Bone::Spine));
  CHECK(std::abs(t_hit - expected) <= 2.0 * humanoid().timestep_s);
  CHECK(std::abs(t_hit - spec.distance_m / spec.speed_mps) < 0.03);
  CHECK(scalar > 0.5 * m * spec.speed_mps);  // at least the approach momentum stopped
  CHECK((dp + on_bones).norm() < 0.05 * dp.norm());
  CHECK(dp.x() > 0.0);  // pushed back towards where it came from
}

TEST_CASE("a cube dropped on the right hand lands after sqrt(2 h / g) and then weighs m g on it") {
  const TickInput in = rest_input();
  AvatarController c = settled(in, {1.0, 1.0, 1.0, 1.0});
  DropCube spec;        // 8 cm, 0.3 m above the hand
  spec.mass_kg = 0.25;  // light enough for the hand's compliant drive to hold level (1 kg tips it off)
  const SpawnResult r = c.drop_cube(spec);
  REQUIRE(r.ok());
  const double t0 = c.sim_b().time_s;
  const double g = -humanoid().gravity.z();
  const double expected = std::sqrt(2.0 * spec.height_m / g);
  double t_land = -1.0, carried = 0.0;
  int carried_ticks = 0;
  for (int k = 0; k < 1200; ++k) {
    const TickOutput& o = c.tick(in);
    REQUIRE(all_finite(o));
    const Hit h = hit_by(o, r.id);
    if (t_land < 0.0 && h.scalar > 0.0) {
      t_land = o.time_s - t0;
      CHECK(h.first == Bone::RightHand);
    }
    if (k >= 1000) {  // settled: the hand carries the cube
      carried += h.on_bones.z();
      ++carried_ticks;
    }
  }
  const double weight = carried / (carried_ticks * humanoid().timestep_s);
  MESSAGE("cube: lands after " << t_land * 1e3 << " ms (sqrt(2h/g) = " << expected * 1e3
                               << " ms); then pushes the hand " << weight << " N down (m g = " << spec.mass_kg * g
                               << " N)");
  CHECK(std::abs(t_land - expected) <= 3.0 * humanoid().timestep_s);
  CHECK(-weight == doctest::Approx(spec.mass_kg * g).epsilon(0.05));
  CHECK(c.gift_count() == 1);  // lifetime 0: stays
}

TEST_CASE("a gift with a lifetime of 0.5 s is gone 0.5 s later") {
  const TickInput in = rest_input();
  AvatarController c = settled(in);
  DropCube spec;
  spec.target = Bone::Head;
  spec.lifetime_s = 0.5;
  const SpawnResult r = c.drop_cube(spec);
  REQUIRE(r.ok());
  const SpawnResult keep = c.drop_cube(DropCube{});  // on the hand, no lifetime
  REQUIRE(keep.ok());
  CHECK(c.gift_count() == 2);
  const double t0 = c.sim_b().time_s;
  int expired_at = -1;
  for (int k = 1; k <= 700; ++k) {
    const TickOutput& o = c.tick(in);
    if ((o.flags & kGiftExpired) != 0) {
      CHECK(expired_at < 0);  // once
      expired_at = k;
      CHECK(o.time_s - t0 >= 0.5 - 1e-9);  // not before its time ...
    }
    CHECK(c.gift_count() == (expired_at < 0 ? 2 : 1));
  }
  CHECK((expired_at == 500 || expired_at == 501));  // ... and on the tick it comes (B's clock sums 1 ms steps)
  CHECK(c.stats().gifts_expired == 1);
  CHECK(sim::find_object(c.sim_b(), {r.id.slot, r.id.generation}) == nullptr);
  CHECK(sim::active_object_count(c.sim_b()) == 1);
  CHECK(c.remove(r.id) == GiftError::not_found);
  CHECK(c.remove(keep.id) == GiftError::none);
  CHECK(c.gift_count() == 0);
}

TEST_CASE("over capacity one more gift is refused and every other is untouched") {
  const TickInput in = rest_input();
  AvatarController c = settled(in);
  constexpr auto kFull = static_cast<int>(sim::kMaxObjects);
  std::vector<GiftId> ids;
  for (size_t k = 0; k < sim::kMaxObjects; ++k) {
    SpawnResult r;
    if (k % 2 == 0) {
      DropCube d;
      d.target = static_cast<Bone>(1 + k % (sim::kBoneCount - 1));
      r = c.drop_cube(d);
    } else {
      ThrowBall b;
      b.target = static_cast<Bone>(1 + k % (sim::kBoneCount - 1));
      r = c.throw_ball(b);
    }
    REQUIRE(r.ok());
    ids.push_back(r.id);
  }
  CHECK(c.gift_count() == kFull);
  const std::array<sim::Object, sim::kMaxObjects> before = c.sim_b().objects;
  const std::uint64_t refused = c.stats().gifts_refused;
  const SpawnResult extra = c.throw_ball(ThrowBall{});
  CHECK(extra.error == GiftError::full);
  CHECK_FALSE(extra.id.valid());
  CHECK(c.drop_cube(DropCube{}).error == GiftError::full);
  CHECK(c.stats().gifts_refused == refused + 2);
  CHECK(c.stats().gifts_spawned == static_cast<std::uint64_t>(kFull));
  CHECK(c.gift_count() == kFull);
  for (size_t k = 0; k < sim::kMaxObjects; ++k) {
    const sim::Object& o = c.sim_b().objects[k];
    CHECK(o.active);
    CHECK(o.generation == before[k].generation);
    CHECK(o.pos == before[k].pos);
    CHECK(o.lin_vel == before[k].lin_vel);
    CHECK(o.mass_kg == before[k].mass_kg);
  }
  // One removed: room for one more.
  CHECK(c.remove(ids[3]) == GiftError::none);
  CHECK(c.throw_ball(ThrowBall{}).ok());
  CHECK(c.gift_count() == kFull);
}

TEST_CASE(
    "remove() of a stale id returns not_found and leaves the slot's newer gift alone, and clear_gifts() empties") {
  const TickInput in = rest_input();
  AvatarController c = settled(in);
  const SpawnResult old = c.drop_cube(DropCube{});
  REQUIRE(old.ok());
  c.tick(in);
  CHECK(c.remove(old.id) == GiftError::none);
  CHECK(c.gift_count() == 0);
  const SpawnResult newer = c.throw_ball(ThrowBall{});
  REQUIRE(newer.ok());
  REQUIRE(newer.id.slot == old.id.slot);            // the slot is reused ...
  CHECK(newer.id.generation != old.id.generation);  // ... under a new generation
  CHECK(c.remove(old.id) == GiftError::not_found);
  CHECK(c.gift_count() == 1);
  CHECK(sim::find_object(c.sim_b(), {newer.id.slot, newer.id.generation}) != nullptr);
  CHECK(c.remove(GiftId{}) == GiftError::not_found);
  CHECK(c.remove(GiftId{99, 1}) == GiftError::not_found);
  CHECK(c.remove(GiftId{-5, 1}) == GiftError::not_found);

  for (int k = 0; k < 5; ++k) REQUIRE(c.drop_cube(DropCube{}).ok());
  CHECK(c.gift_count() == 6);
  c.clear_gifts();
  CHECK(c.gift_count() == 0);
  CHECK(sim::active_object_count(c.sim_b()) == 0);
  CHECK(c.remove(newer.id) == GiftError::not_found);
  for (int k = 0; k < 10; ++k) CHECK(c.tick(in).nevents == 0);
}
