// Stiffness -> gains against closed forms and the sim's own CRBA; group table, rate limit, bad values, validate().
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "avatar_fixtures.hpp"
#include "tonus/host/avatar/stiffness.hpp"
#include "tonus/sim/step.hpp"

using namespace tonus;
using namespace tonus::avatar;
using avatar::test::humanoid;
using sim::Bone;
using std::size_t;

namespace {

constexpr double kTwoPi = 2.0 * M_PI;

// The joint-space inertia's diagonal at the rest pose, computed here with the sim's own CRBA.
std::array<double, sim::kMaxDofs> rest_inertia() {
  const sim::Model& m = humanoid();
  auto d = sim::make_data(m);
  sim::forward_kinematics(m, *d);
  sim::mass_matrix(m, *d);
  std::array<double, sim::kMaxDofs> out{};
  const auto nv = static_cast<size_t>(m.nv);
  for (size_t k = 0; k < nv; ++k) out[k] = d->mass[k * nv + k];
  return out;
}

std::array<double, kGroupCount> all(double s) { return {s, s, s, s}; }

}  // namespace

TEST_CASE("the frequency runs from min_hz to max_hz on a log scale") {
  const StiffnessConfig c = default_stiffness_config();
  const StiffnessMapper map(humanoid(), c);
  for (size_t g = 0; g < kGroupCount; ++g) {
    const GroupCurve& k = c.curves[g];
    CHECK(map.frequency_hz(g, 0.0) == doctest::Approx(k.min_hz).epsilon(1e-12));
    CHECK(map.frequency_hz(g, 1.0) == doctest::Approx(k.max_hz).epsilon(1e-12));
    CHECK(map.frequency_hz(g, 0.5) == doctest::Approx(std::sqrt(k.min_hz * k.max_hz)).epsilon(1e-12));
    CHECK(map.frequency_hz(g, 0.25) == doctest::Approx(k.min_hz * std::pow(k.max_hz / k.min_hz, 0.25)).epsilon(1e-12));
    // Outside 0..1 the curve stops at its ends.
    CHECK(map.frequency_hz(g, -1.0) == doctest::Approx(k.min_hz));
    CHECK(map.frequency_hz(g, 2.0) == doctest::Approx(k.max_hz));
  }
}

TEST_CASE("Kp = (2 pi f)^2 I and Kd = 2 zeta (2 pi f) I per dof, I the joint-space inertia's diagonal at rest") {
  const sim::Model& m = humanoid();
  StiffnessConfig c = default_stiffness_config();
  c.curves[static_cast<size_t>(Group::trunk)].damping_ratio = 0.7;  // a non-critical group too
  StiffnessMapper map(m, c);
  const auto inertia = rest_inertia();
  const auto eff = effective_inertia(m);
  for (const double s : {0.0, 0.3, 0.5, 1.0}) {
    map.set_applied(all(s));
    int driven = 0;
    for (size_t d = 0; d < static_cast<size_t>(m.nv); ++d) {
      CAPTURE(d);
      CHECK(eff[d] == doctest::Approx(inertia[d]).epsilon(1e-12));
      CHECK(map.inertia(d) == doctest::Approx(inertia[d]).epsilon(1e-12));
      if (d < 6) {  // the root's dofs are not driven
        CHECK(map.dof_group(d) == StiffnessMapper::kUndriven);
        CHECK(map.kp(d) == 0.0);
        CHECK(map.kd(d) == 0.0);
        continue;
      }
      const auto g = static_cast<size_t>(map.dof_group(d));
      REQUIRE(g < kGroupCount);
      const GroupCurve& k = c.curves[g];
      const double w = kTwoPi * k.min_hz * std::pow(k.max_hz / k.min_hz, s);
      CHECK(map.kp(d) == doctest::Approx(w * w * inertia[d]).epsilon(1e-12));
      CHECK(map.kd(d) == doctest::Approx(2.0 * k.damping_ratio * w * inertia[d]).epsilon(1e-12));
      // Damping ratio kd / (2 sqrt(kp I)): critical (1) on the default curves at every stiffness.
      const double zeta = map.kd(d) / (2.0 * std::sqrt(map.kp(d) * inertia[d]));
      CHECK(zeta == doctest::Approx(k.damping_ratio).epsilon(1e-12));
      if (g != static_cast<size_t>(Group::trunk)) {
        CHECK(map.kd(d) * map.kd(d) == doctest::Approx(4.0 * map.kp(d) * inertia[d]).epsilon(1e-12));
      }
      ++driven;
    }
    CHECK(driven == m.nv - 6);
  }
}

TEST_CASE("write_gains copies the mapper's gains and the stiff gains use the same inertia") {
  const sim::Model& m = humanoid();
  StiffnessMapper map(m, default_stiffness_config());
  map.set_applied(all(0.8));
  sim::StepInputs in = sim::make_inputs(m);
  map.write_gains(m, in);
  const auto inertia = rest_inertia();
  for (size_t d = 6; d < static_cast<size_t>(m.nv); ++d) {
    CHECK(in.kp[d] == map.kp(d));
    CHECK(in.kd[d] == map.kd(d));
  }
  write_stiff_gains(m, map, {30.0, 20.0, 10.0, 40.0}, 5.0, 1.0, in);
  const double hz[] = {30.0, 20.0, 10.0, 40.0};
  for (size_t d = 6; d < static_cast<size_t>(m.nv); ++d) {
    const double w = kTwoPi * hz[static_cast<size_t>(map.dof_group(d))];
    CHECK(in.kp[d] == doctest::Approx(w * w * inertia[d]).epsilon(1e-12));
    CHECK(in.kd[d] == doctest::Approx(2.0 * w * inertia[d]).epsilon(1e-12));
  }
}

TEST_CASE("the default table: arms, trunk and legs drive their own bones") {
  const sim::Model& m = humanoid();
  const StiffnessConfig c = default_stiffness_config();
  CHECK(validate(c).empty());
  const StiffnessMapper map(m, c);
  const auto group_of = [&](Bone b) {
    const sim::Body& body = m.bodies[sim::index(b)];
    // Every dof of the bone's joint in the same group.
    const int g = map.dof_group(static_cast<size_t>(body.dof_adr));
    for (int k = body.dof_adr; k < body.dof_adr + body.dof_num; ++k) CHECK(map.dof_group(static_cast<size_t>(k)) == g);
    return g;
  };
  const auto is = [](Group g) { return static_cast<int>(g); };
  for (const Bone b : {Bone::RightShoulder, Bone::RightUpperArm, Bone::RightLowerArm, Bone::RightHand}) {
    CAPTURE(sim::name(b));
    CHECK(group_of(b) == is(Group::right_arm));
    CHECK(group_of(sim::mirror(b)) == is(Group::left_arm));
  }
  for (const Bone b : {Bone::Spine, Bone::Chest, Bone::Neck, Bone::Head}) CHECK(group_of(b) == is(Group::trunk));
  for (const Bone b : {Bone::LeftUpperLeg, Bone::LeftLowerLeg, Bone::LeftFoot, Bone::LeftToes, Bone::RightUpperLeg,
                       Bone::RightLowerLeg, Bone::RightFoot, Bone::RightToes}) {
    CHECK(group_of(b) == is(Group::legs));
  }
  CHECK(group_of(Bone::Hips) == StiffnessMapper::kUndriven);
  CHECK(to_string(Group::right_arm) == "right_arm");
}

TEST_CASE("a bone taken out of every group follows the ungrouped curve") {
  const sim::Model& m = humanoid();
  StiffnessConfig c = default_stiffness_config();
  c.bone_group[sim::index(Bone::Neck)] = kNoGroup;
  c.ungrouped = GroupCurve{3.0, 3.0, 0.5};
  StiffnessMapper map(m, c);
  map.set_applied(all(1.0));
  const auto d = static_cast<size_t>(m.bodies[sim::index(Bone::Neck)].dof_adr);
  CHECK(map.dof_group(d) == kNoGroup);
  const double w = kTwoPi * 3.0;
  CHECK(map.kp(d) == doctest::Approx(w * w * map.inertia(d)));
  CHECK(map.kd(d) == doctest::Approx(2.0 * 0.5 * w * map.inertia(d)));
}

TEST_CASE("the rate limit: 0 -> 1 takes 1 / max_rate_per_s, flagged all along") {
  const sim::Model& m = humanoid();
  for (const double rate : {5.0, 20.0}) {
    StiffnessConfig c = default_stiffness_config();
    c.max_rate_per_s = rate;
    StiffnessMapper map(m, c);
    map.set_applied(all(0.0));
    const double dt = m.timestep_s;
    int ticks = 0, flagged = 0;
    double prev = 0.0, largest_step = 0.0;
    while (map.applied()[0] < 1.0 - 1e-12 && ticks < 100000) {
      const StiffnessMapper::Update u = map.update(all(1.0), dt);
      ++ticks;
      flagged += u.rate_limited ? 1 : 0;
      largest_step = std::max(largest_step, map.applied()[0] - prev);
      prev = map.applied()[0];
    }
    const double expected = 1.0 / (rate * dt);
    MESSAGE("rate " << rate << "/s: 0 -> 1 in " << ticks << " ticks (expected " << expected << ")");
    CHECK(std::abs(ticks - expected) <= 1.0);
    CHECK(flagged >= ticks - 1);  // every tick but possibly the last (which lands exactly)
    CHECK(largest_step <= rate * dt * (1.0 + 1e-9));
    CHECK(map.applied()[0] == doctest::Approx(1.0).epsilon(1e-9));
    // Settled: no longer flagged.
    CHECK_FALSE(map.update(all(1.0), dt).rate_limited);
    CHECK_FALSE(map.update(all(1.0), dt).rate_limited);
  }
}

TEST_CASE("the controller rate-limits the applied stiffness and flags it") {
  AvatarConfig cfg;
  cfg.stiffness.max_rate_per_s = 5.0;
  AvatarController c = avatar::test::make_controller(cfg);
  c.set_stiffness_now(all(0.0));
  TickInput in;
  in.reference = rest_reference(humanoid());
  in.stiffness = all(1.0);
  int flagged = 0, ticks = 0;
  while (c.output().stiffness[0] < 1.0 - 1e-12 && ticks < 1000) {
    flagged += (c.tick(in).flags & kStiffnessRateLimited) ? 1 : 0;
    ++ticks;
  }
  MESSAGE("controller: 0 -> 1 in " << ticks << " ticks at 5/s");
  CHECK(std::abs(ticks * humanoid().timestep_s - 0.2) <= humanoid().timestep_s + 1e-12);
  CHECK(flagged >= ticks - 1);
  CHECK((c.tick(in).flags & kStiffnessRateLimited) == 0);
}

TEST_CASE("stiffness outside 0..1 is clamped and counted, NaN is ignored (the last valid kept) and counted") {
  const sim::Model& m = humanoid();
  StiffnessMapper map(m, default_stiffness_config());
  StiffnessMapper::Update u = map.update({-3.0, 7.0, 0.5, 0.25}, m.timestep_s);
  CHECK(u.clamped == 2);
  CHECK(u.rejected == 0);
  CHECK(map.target()[0] == 0.0);
  CHECK(map.target()[1] == 1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  u = map.update({nan, inf, -inf, 0.25}, m.timestep_s);
  CHECK(u.rejected == 3);
  CHECK(u.clamped == 0);
  CHECK(map.target()[0] == 0.0);  // kept from the last valid value
  CHECK(map.target()[1] == 1.0);
  CHECK(map.target()[2] == 0.5);
  CHECK(map.target()[3] == 0.25);
  for (size_t g = 0; g < kGroupCount; ++g) CHECK(std::isfinite(map.applied()[g]));
  for (size_t d = 0; d < static_cast<size_t>(m.nv); ++d) CHECK((std::isfinite(map.kp(d)) && std::isfinite(map.kd(d))));
  // set_inertia ignores non-finite and non-positive entries.
  std::array<double, sim::kMaxDofs * sim::kMaxDofs> mass{};
  const double before = map.inertia(10);
  map.set_inertia(mass, m.nv);
  CHECK(map.inertia(10) == before);
}

TEST_CASE("validate() refuses a bad stiffness config with a message naming the field") {
  const auto expect = [](StiffnessConfig c, const char* field) {
    const std::string e = validate(c);
    CAPTURE(e);
    CHECK(e.find(field) != std::string::npos);
  };
  StiffnessConfig c = default_stiffness_config();
  CHECK(validate(c).empty());
  c.curves[1].min_hz = -1.0;
  expect(c, "curves.left_arm");
  c = default_stiffness_config();
  c.curves[3].max_hz = std::numeric_limits<double>::quiet_NaN();
  expect(c, "curves.legs");
  c = default_stiffness_config();
  c.curves[0].min_hz = 5.0;
  c.curves[0].max_hz = 4.0;  // max below min
  expect(c, "curves.right_arm");
  c = default_stiffness_config();
  c.ungrouped.damping_ratio = -0.1;
  expect(c, "ungrouped");
  c = default_stiffness_config();
  c.bone_group[sim::index(Bone::Head)] = 4;
  expect(c, "bone_group.Head");
  c = default_stiffness_config();
  c.max_rate_per_s = 0.0;
  expect(c, "max_rate_per_s");
  c = default_stiffness_config();
  c.initial = 1.5;
  expect(c, "initial");

  // The controller refuses it too, naming the field.
  AvatarConfig a;
  a.stiffness.max_rate_per_s = -1.0;
  AvatarController::Created made = AvatarController::create(humanoid(), a);
  CHECK_FALSE(made);
  CHECK(made.error.find("max_rate_per_s") != std::string::npos);
  a = AvatarConfig{};
  a.jump_rad = 0.0;
  made = AvatarController::create(humanoid(), a);
  CHECK_FALSE(made);
  CHECK(made.error.find("jump_rad") != std::string::npos);
  a = AvatarConfig{};
  a.feedforward = Feedforward::inverse_dynamics;
  a.id_lag_ticks = 0;
  made = AvatarController::create(humanoid(), a);
  CHECK_FALSE(made);
  CHECK(made.error.find("id_lag_ticks") != std::string::npos);
}
