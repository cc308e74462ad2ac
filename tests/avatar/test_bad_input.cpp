// Bad input (references, stiffness, gift parameters, teleports, garbage streams) never reaches the outputs.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include "avatar_fixtures.hpp"
#include "tonus/sim/objects.hpp"

using namespace tonus;
using namespace tonus::avatar;
using namespace tonus::avatar::test;
using sim::Bone;
using std::size_t;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

size_t qpos_of(Bone b) { return static_cast<size_t>(humanoid().bodies[sim::index(b)].qpos_adr); }
size_t dof_of(Bone b) { return static_cast<size_t>(humanoid().bodies[sim::index(b)].dof_adr); }

}  // namespace

TEST_CASE("a broken reference is refused: flagged, the last valid one kept, no NaN out") {
  struct Case {
    const char* what;
    std::function<void(ReferencePose&)> breaks;
  };
  const std::vector<Case> cases = {
      {"NaN joint angle", [](ReferencePose& r) { r.qpos[qpos_of(Bone::RightLowerArm)] = kNaN; }},
      {"infinite root position", [](ReferencePose& r) { r.qpos[1] = kInf; }},
      {"root 1000 km away", [](ReferencePose& r) { r.qpos[0] = 1e6; }},
      {"zero ball quaternion", [](ReferencePose& r) { std::fill_n(&r.qpos[qpos_of(Bone::LeftUpperArm)], 4, 0.0); }},
      {"zero root quaternion", [](ReferencePose& r) { std::fill_n(&r.qpos[3], 4, 0.0); }},
      {"NaN in a quaternion", [](ReferencePose& r) { r.qpos[qpos_of(Bone::Neck) + 2] = kNaN; }},
      {"NaN velocity",
       [](ReferencePose& r) {
         r.has_velocity = true;
         r.qvel[dof_of(Bone::RightHand) + 1] = kNaN;
       }},
      {"infinite root velocity",
       [](ReferencePose& r) {
         r.has_velocity = true;
         r.qvel[0] = -kInf;
       }},
  };
  const ReferencePose good = arms_lowered(0.5, 0.8);
  for (const Case& k : cases) {
    CAPTURE(k.what);
    AvatarController c = make_controller();
    TickInput in;
    in.reference = good;
    for (int t = 0; t < 100; ++t) c.tick(in);
    const std::array<double, sim::kMaxQpos> kept = c.output().reference_qpos;
    in.reference = good;
    k.breaks(in.reference);
    for (int t = 0; t < 50; ++t) {
      const TickOutput& o = c.tick(in);
      REQUIRE((o.flags & kReferenceInvalid) != 0);
      CHECK((o.flags & kReferenceJump) == 0);
      REQUIRE(all_finite(o));
      CHECK(o.reference_qpos == kept);
    }
    CHECK(c.stats().reference_invalid == 50);
    double worst = 0.0;
    for (size_t b = 1; b < sim::kBoneCount; ++b) worst = std::max(worst, c.output().deviation_rad[b]);
    CHECK(worst < 0.01);  // B held the last valid pose
    in.reference = good;
    const TickOutput& o = c.tick(in);
    CHECK((o.flags & (kReferenceInvalid | kReferenceJump)) == 0);
    CHECK(c.stats().reference_jumps == 0);
  }
}

TEST_CASE("an unnormalised but usable quaternion is accepted and normalised") {
  AvatarController c = make_controller();
  TickInput in;
  in.reference = rest_reference(humanoid());
  const size_t a = qpos_of(Bone::Spine);
  for (size_t k = 0; k < 4; ++k) in.reference.qpos[a + k] *= 1.5;
  const TickOutput& o = c.tick(in);
  CHECK((o.flags & kReferenceInvalid) == 0);
  const double n =
      std::sqrt(o.reference_qpos[a] * o.reference_qpos[a] + o.reference_qpos[a + 1] * o.reference_qpos[a + 1] +
                o.reference_qpos[a + 2] * o.reference_qpos[a + 2] + o.reference_qpos[a + 3] * o.reference_qpos[a + 3]);
  CHECK(n == doctest::Approx(1.0).epsilon(1e-14));
}

TEST_CASE("stiffness NaN / -3 / 7: flagged and counted, the applied values stay in 0..1") {
  AvatarController c = make_controller();
  c.set_stiffness_now({0.3, 0.3, 0.3, 0.3});
  TickInput in;
  in.reference = rest_reference(humanoid());
  in.stiffness = {kNaN, -3.0, 7.0, 0.5};
  const TickOutput& o = c.tick(in);
  CHECK((o.flags & kStiffnessInvalid) != 0);
  CHECK((o.flags & kStiffnessClamped) != 0);
  CHECK((o.flags & kStiffnessRateLimited) != 0);
  CHECK(c.stats().stiffness_invalid == 1);
  CHECK(c.stats().stiffness_clamped == 2);
  // One tick of the rate limit from 0.3: NaN holds, -3 -> 0 and 7 -> 1 move by rate * dt.
  const double step = c.config().stiffness.max_rate_per_s * humanoid().timestep_s;
  CHECK(o.stiffness[0] == doctest::Approx(0.3));
  CHECK(o.stiffness[1] == doctest::Approx(0.3 - step));
  CHECK(o.stiffness[2] == doctest::Approx(0.3 + step));
  CHECK(o.stiffness[3] == doctest::Approx(0.3 + step));
  in.stiffness = {kInf, -kInf, kNaN, 0.5};
  for (int t = 0; t < 300; ++t) {
    const TickOutput& p = c.tick(in);
    REQUIRE(all_finite(p));
    for (const double s : p.stiffness) CHECK((s >= 0.0 && s <= 1.0));
  }
  CHECK(c.stats().stiffness_invalid == 1 + 300 * 3);
  CHECK(c.output().stiffness[1] == 0.0);  // -3 was the last valid request: clamped to 0 and reached
  CHECK(c.output().stiffness[2] == 1.0);
}

TEST_CASE("absurd gift parameters are refused with bad_params and nothing is spawned") {
  AvatarController c = make_controller();
  TickInput in;
  in.reference = rest_reference(humanoid());
  c.tick(in);
  const std::vector<std::function<void(ThrowBall&)>> balls = {
      [](ThrowBall& b) { b.mass_kg = kNaN; },    [](ThrowBall& b) { b.mass_kg = -1.0; },
      [](ThrowBall& b) { b.mass_kg = 0.0; },     [](ThrowBall& b) { b.mass_kg = 1e9; },
      [](ThrowBall& b) { b.radius_m = -0.1; },   [](ThrowBall& b) { b.radius_m = 50.0; },
      [](ThrowBall& b) { b.speed_mps = 0.0; },   [](ThrowBall& b) { b.speed_mps = 3e8; },
      [](ThrowBall& b) { b.speed_mps = kInf; },  [](ThrowBall& b) { b.distance_m = -1.5; },
      [](ThrowBall& b) { b.distance_m = kNaN; }, [](ThrowBall& b) { b.lifetime_s = -1.0; },
      [](ThrowBall& b) { b.lifetime_s = kNaN; }, [](ThrowBall& b) { b.direction = sim::Vec3(kNaN, 0, 0); },
      [](ThrowBall& b) { b.restitution = 1.5; }, [](ThrowBall& b) { b.restitution = kNaN; },
      [](ThrowBall& b) { b.friction = -0.1; },   [](ThrowBall& b) { b.friction = kInf; },
  };
  const std::vector<std::function<void(DropCube&)>> cubes = {
      [](DropCube& d) { d.mass_kg = kNaN; },    [](DropCube& d) { d.mass_kg = -1.0; },
      [](DropCube& d) { d.mass_kg = 1e9; },     [](DropCube& d) { d.edge_m = 0.0; },
      [](DropCube& d) { d.edge_m = 100.0; },    [](DropCube& d) { d.height_m = -0.3; },
      [](DropCube& d) { d.height_m = kNaN; },   [](DropCube& d) { d.height_m = 1e6; },
      [](DropCube& d) { d.lifetime_s = kInf; }, [](DropCube& d) { d.lifetime_s = -2.0; },
      [](DropCube& d) { d.friction = kNaN; },
  };
  int refused = 0;
  for (size_t k = 0; k < balls.size(); ++k) {
    CAPTURE(k);
    ThrowBall b;
    balls[k](b);
    const SpawnResult r = c.throw_ball(b);
    CHECK(r.error == GiftError::bad_params);
    CHECK_FALSE(r.id.valid());
    ++refused;
  }
  for (size_t k = 0; k < cubes.size(); ++k) {
    CAPTURE(k);
    DropCube d;
    cubes[k](d);
    const SpawnResult r = c.drop_cube(d);
    CHECK(r.error == GiftError::bad_params);
    ++refused;
  }
  for (const int bone : {21, 200, 255}) {
    ThrowBall b;
    b.target = static_cast<Bone>(bone);
    CHECK(c.throw_ball(b).error == GiftError::bad_target);
    DropCube d;
    d.target = static_cast<Bone>(bone);
    CHECK(c.drop_cube(d).error == GiftError::bad_target);
    refused += 2;
  }
  CHECK(c.gift_count() == 0);
  CHECK(sim::active_object_count(c.sim_b()) == 0);
  CHECK(c.stats().gifts_refused == static_cast<std::uint64_t>(refused));
  CHECK(c.stats().gifts_spawned == 0);
  CHECK(to_string(GiftError::bad_params).size() > 0);
}

TEST_CASE("a throw's direction is a direction whatever its length") {
  AvatarController c = make_controller();
  TickInput in;
  in.reference = rest_reference(humanoid());
  c.tick(in);
  ThrowBall unit;
  unit.direction = sim::Vec3(-1.0, 0.0, 0.0);
  const SpawnResult a = c.throw_ball(unit);
  ThrowBall huge = unit;
  huge.direction = sim::Vec3(-1e300, 0.0, 0.0);
  const SpawnResult b = c.throw_ball(huge);
  ThrowBall tiny = unit;
  tiny.direction = sim::Vec3(-1e-6, 0.0, 0.0);
  const SpawnResult t = c.throw_ball(tiny);
  REQUIRE((a.ok() && b.ok() && t.ok()));
  const sim::Object& oa = c.sim_b().objects[static_cast<size_t>(a.id.slot)];
  for (const SpawnResult& r : {b, t}) {
    const sim::Object& o = c.sim_b().objects[static_cast<size_t>(r.id.slot)];
    CHECK((o.pos - oa.pos).norm() < 1e-12);
    CHECK((o.lin_vel - oa.lin_vel).norm() < 1e-12);
  }
}

TEST_CASE("a teleport of the root by 2 m is a jump: A and B resynced there") {
  AvatarController c = make_controller();
  TickInput in;
  in.reference = arms_lowered(0.6, 0.4);
  for (int t = 0; t < 200; ++t) c.tick(in);
  in.reference.qpos[0] += 2.0;
  const TickOutput& o = c.tick(in);
  CHECK((o.flags & kReferenceJump) != 0);
  CHECK(c.stats().reference_jumps == 1);
  for (size_t k = 0; k < 3; ++k) CHECK(o.qpos[k] == doctest::Approx(in.reference.qpos[k]).epsilon(1e-12));
  CHECK(c.sim_a().qpos[0] == doctest::Approx(in.reference.qpos[0]));
  const sim::Vec3 hand = com_of(in.reference.qpos, Bone::RightHand);
  CHECK((com_of(o, Bone::RightHand) - hand).norm() < 2e-3);
  for (int t = 0; t < 300; ++t) {
    const TickOutput& p = c.tick(in);
    CHECK((p.flags & (kReferenceJump | kResetB)) == 0);
    CHECK(std::abs(p.qvel[0]) < 0.1);  // no fling along the teleport
  }
  CHECK((com_of(c.output(), Bone::RightHand) - hand).norm() < 2e-3);
}

TEST_CASE("10,000 ticks of garbage mixed with valid input: no crash, never a NaN out") {
  AvatarController c = make_controller();
  const sim::Model& m = humanoid();
  std::mt19937 rng(20240611);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto pick = [&](std::initializer_list<double> xs) {
    return *(xs.begin() + static_cast<long>(rng() % xs.size()));
  };
  const double garbage[] = {kNaN, kInf, -kInf, 1e300, -1e300, 0.0, 1e5};
  ReferencePose current = rest_reference(m);
  std::vector<GiftId> ids;
  int flagged_invalid = 0, jumps = 0, worst_quat_ticks = 0;
  for (int t = 0; t < 10000; ++t) {
    TickInput in;
    const double r = u(rng);
    // A valid pose: every joint swinging smoothly about the rest pose, now and
    // then far out of its range for a moment (clamped, and a jump there and back).
    const double time = t * m.timestep_s;
    const double far = (t % 700) < 5 ? 3.0 : 1.0;
    for (int i = 1; i < m.nbody; ++i) {
      const sim::Body& b = m.bodies[static_cast<size_t>(i)];
      const auto a = static_cast<size_t>(b.qpos_adr);
      const double phase = 0.7 * i;
      if (b.joint == sim::JointType::hinge) current.qpos[a] = far * (0.8 + 0.6 * std::sin(2.0 * time + phase));
      if (b.joint == sim::JointType::ball) {
        const sim::Vec3 w = far * 0.4 *
                            sim::Vec3(std::sin(1.1 * time + phase), std::sin(1.7 * time + 2.0 * phase),
                                      std::sin(0.9 * time + 3.0 * phase));
        const sim::Quat n = sim::quat_exp(w);
        current.qpos[a] = n.w();
        current.qpos[a + 1] = n.x();
        current.qpos[a + 2] = n.y();
        current.qpos[a + 3] = n.z();
      }
    }
    if (u(rng) < 0.002) current.qpos[0] += 3.0 * (u(rng) - 0.5);  // a teleport
    current.has_velocity = u(rng) < 0.3;
    for (size_t k = 0; k < static_cast<size_t>(m.nv); ++k) current.qvel[k] = current.has_velocity ? u(rng) - 0.5 : 0.0;
    in.reference = current;
    if (r > 0.6) {  // garbage: a few entries broken, or everything random
      const int n = 1 + static_cast<int>(rng() % 3);
      for (int k = 0; k < n; ++k) {
        const double g = garbage[rng() % std::size(garbage)];
        if (u(rng) < 0.5) {
          in.reference.qpos[rng() % static_cast<size_t>(m.nq)] = g;
        } else {
          in.reference.has_velocity = true;
          in.reference.qvel[rng() % static_cast<size_t>(m.nv)] = g;
        }
      }
      if (r > 0.95) {
        for (size_t k = 0; k < static_cast<size_t>(m.nq); ++k) in.reference.qpos[k] = 4.0 * (u(rng) - 0.5);
      }
    }
    for (double& s : in.stiffness) s = u(rng) < 0.2 ? pick({kNaN, kInf, -3.0, 7.0, -kInf}) : u(rng);
    // Gifts with short lives (a handful at a time: the run is about bad input, not a crowd).
    if (t % 250 == 0) {
      ThrowBall b;
      b.target = static_cast<Bone>(rng() % 23);  // 21, 22: no such bone
      b.mass_kg = pick({0.45, 5.0, 1000.0, -1.0, kNaN});
      b.speed_mps = pick({8.0, 30.0, 100.0, 0.0});
      b.radius_m = pick({0.11, 0.02, 1.0});
      b.direction = sim::Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
      b.lifetime_s = pick({0.3, 1.0, -1.0});
      const SpawnResult s = c.throw_ball(b);
      if (s.ok()) ids.push_back(s.id);
    }
    if (t % 400 == 0) {
      DropCube d;
      d.lifetime_s = 1.0;
      d.target = static_cast<Bone>(rng() % 21);
      d.mass_kg = pick({1.0, 20.0, 1e4});
      d.edge_m = pick({0.08, 0.3});
      d.height_m = pick({0.0, 0.3, 2.0});
      const SpawnResult s = c.drop_cube(d);
      if (s.ok()) ids.push_back(s.id);
    }
    if (t % 300 == 0 && !ids.empty()) (void)c.remove(ids[rng() % ids.size()]);  // live or stale
    if (t % 2500 == 2499) c.clear_gifts();
    const TickOutput& o = c.tick(in);
    REQUIRE(all_finite(o));
    flagged_invalid += (o.flags & kReferenceInvalid) != 0 ? 1 : 0;
    jumps += (o.flags & kReferenceJump) != 0 ? 1 : 0;
    for (int i = 0; i < m.nbody; ++i) {  // B's quaternions stay unit
      const sim::Body& b = m.bodies[static_cast<size_t>(i)];
      if (b.joint != sim::JointType::ball && b.joint != sim::JointType::free) continue;
      const auto a = static_cast<size_t>(b.qpos_adr) + (b.joint == sim::JointType::free ? 3U : 0U);
      const double n = std::sqrt(o.qpos[a] * o.qpos[a] + o.qpos[a + 1] * o.qpos[a + 1] + o.qpos[a + 2] * o.qpos[a + 2] +
                                 o.qpos[a + 3] * o.qpos[a + 3]);
      worst_quat_ticks += std::abs(n - 1.0) > 1e-6 ? 1 : 0;
    }
    for (const double s : o.stiffness) REQUIRE((s >= 0.0 && s <= 1.0));
  }
  const AvatarStats& s = c.stats();
  MESSAGE("garbage run: " << s.reference_invalid << " references refused, " << s.reference_clamped << " clamped, "
                          << s.reference_jumps << " jumps, " << s.stiffness_invalid << " stiffness ignored, "
                          << s.stiffness_clamped << " clamped, " << s.gifts_spawned << " gifts spawned, "
                          << s.gifts_refused << " refused, " << s.resets_b << " resets of B, " << s.resets_a
                          << " of A");
  CHECK(s.ticks == 10000);
  CHECK(worst_quat_ticks == 0);
  CHECK(static_cast<std::uint64_t>(flagged_invalid) == s.reference_invalid);
  CHECK(static_cast<std::uint64_t>(jumps) == s.reference_jumps);
  CHECK(s.reference_invalid > 2000);
  CHECK(s.reference_jumps > 10);
  CHECK(s.reference_clamped > 100);
  CHECK(s.stiffness_invalid > 100);
  CHECK(s.stiffness_clamped > 100);
  CHECK(s.gifts_spawned > 10);
  CHECK(s.gifts_refused > 5);
}
