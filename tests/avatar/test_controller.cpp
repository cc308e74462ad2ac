// The dual PD controller: static hold, bounded feedforward, jump resync, PD+FF vs PD, inverse dynamics, free root.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "avatar_fixtures.hpp"
#include "tonus/sim/step.hpp"

using namespace tonus;
using namespace tonus::avatar;
using namespace tonus::avatar::test;
using sim::Bone;
using std::size_t;

namespace {

size_t dof_of(Bone b) { return static_cast<size_t>(humanoid().bodies[sim::index(b)].dof_adr); }
size_t qpos_of(Bone b) { return static_cast<size_t>(humanoid().bodies[sim::index(b)].qpos_adr); }

// Gravity torques at a configuration at rest (RNEA with zero velocity and acceleration).
std::array<double, sim::kMaxDofs> gravity_torques(std::span<const double> qpos) {
  const sim::Model& m = humanoid();
  auto d = sim::make_data(m);
  std::copy_n(qpos.begin(), m.nq, d->qpos.begin());
  sim::forward_kinematics(m, *d);
  std::array<double, sim::kMaxDofs> zero{}, tau{};
  sim::inverse_dynamics(m, *d, zero, tau);
  return tau;
}

// Runs `ticks` ticks of one input; returns the largest worst_limit_ratio of tau_ff.
double run(AvatarController& c, const TickInput& in, int ticks) {
  double worst = 0.0;
  for (int k = 0; k < ticks; ++k) worst = std::max(worst, worst_limit_ratio(c.tick(in).tau_ff));
  return worst;
}

}  // namespace

TEST_CASE("holding the rest pose: B stays on the reference and tau_ff is A's applied torque (gravity)") {
  AvatarController c = make_controller();
  TickInput in;
  in.reference = rest_reference(humanoid());
  double worst_dev = 0.0, worst_hand_m = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const TickOutput& o = c.tick(in);
    REQUIRE(all_finite(o));
    REQUIRE((o.flags & (kFeedforwardClamped | kResetB | kResetA | kReferenceJump)) == 0);
    for (size_t d = 6; d < static_cast<size_t>(humanoid().nv); ++d) REQUIRE(o.tau_ff[d] == o.tau_a[d]);
    if (k < 200) continue;
    for (size_t b = 1; b < sim::kBoneCount; ++b) worst_dev = std::max(worst_dev, o.deviation_rad[b]);
    for (const Bone h : {Bone::RightHand, Bone::LeftHand, Bone::Head}) {
      worst_hand_m = std::max(worst_hand_m, (com_of(o, h) - com_of(in.reference.qpos, h)).norm());
    }
  }
  const TickOutput& o = c.output();
  // Independent: A's torque at a static hold is the gravity torque of the pose (RNEA).
  const auto g = gravity_torques(in.reference.qpos);
  double g_max = 0.0, diff = 0.0;
  for (size_t d = 6; d < static_cast<size_t>(humanoid().nv); ++d) {
    g_max = std::max(g_max, std::abs(g[d]));
    diff = std::max(diff, std::abs(o.tau_ff[d] - g[d]));
  }
  MESSAGE("rest hold: largest joint deviation " << worst_dev << " rad, hands/head " << worst_hand_m * 1e3
                                                << " mm; tau_ff vs gravity " << diff << " of " << g_max << " N*m");
  CHECK(worst_dev < 2e-3);
  CHECK(worst_hand_m < 1e-3);
  CHECK(diff < 0.01 * g_max);
  CHECK(c.stats().ticks == 1000);
}

TEST_CASE("a reference beyond a joint's range is clamped, and no |tau_ff| exceeds its joint's torque limit") {
  AvatarController c = make_controller();
  TickInput in;
  in.reference = rest_reference(humanoid());
  in.reference.has_velocity = false;
  const size_t elbow = qpos_of(Bone::RightLowerArm);
  const double upper = humanoid().bodies[sim::index(Bone::RightLowerArm)].limit.upper_rad;
  REQUIRE(upper == doctest::Approx(2.6));
  double worst = 0.0, worst_b = 0.0;
  int clamped = 0;
  for (int k = 0; k < 1800; ++k) {
    // 0 -> 3.5 rad at 3 rad/s (no jump), then held at 3.5.
    in.reference.qpos[elbow] = std::min(3.5, 3.0 * k * humanoid().timestep_s);
    const TickOutput& o = c.tick(in);
    REQUIRE(all_finite(o));
    if (in.reference.qpos[elbow] > upper) {
      CHECK((o.flags & kReferenceClamped) != 0);
      CHECK(o.reference_qpos[elbow] == doctest::Approx(upper));
      ++clamped;
    }
    worst = std::max(worst, worst_limit_ratio(o.tau_ff));
    worst_b = std::max(worst_b, worst_limit_ratio(o.tau_b));
  }
  MESSAGE("elbow asked 3.5 rad: largest |tau_ff| / limit " << worst << ", |tau_b| / limit " << worst_b << "; B's elbow "
                                                           << c.output().qpos[elbow]);
  CHECK(clamped > 500);
  CHECK(c.stats().reference_clamped == static_cast<std::uint64_t>(clamped));
  CHECK(worst <= 1.0 + 1e-12);
  CHECK(worst_b <= 1.0 + 1e-6);  // B's drives meet their limits too (the sim's bounded rows)
  CHECK(c.output().qpos[elbow] == doctest::Approx(upper).epsilon(0.02));
}

TEST_CASE("a step in the reference is a jump: A and B resynced, no torque transient (without the check, a big one)") {
  const ReferencePose held = arms_lowered(1.2, 1.5);
  const sim::Vec3 hand_ref = com_of(held.qpos, Bone::RightHand);
  double worst_with = 0.0, worst_without = 0.0, asked_with = 0.0, asked_without = 0.0;
  for (const bool detect : {true, false}) {
    AvatarConfig cfg;
    if (!detect) cfg.jump_rad = cfg.jump_m = 1e9;
    AvatarController c = make_controller(cfg);
    TickInput in;
    in.reference = rest_reference(humanoid());
    const double before = run(c, in, 200);
    in.reference = held;
    const TickOutput& o = c.tick(in);
    const bool jumped = (o.flags & kReferenceJump) != 0;
    double worst = std::max(before, worst_limit_ratio(o.tau_ff));
    double asked = worst_limit_ratio(o.tau_a);  // A's own torque: unlimited, what the step asks for
    bool clamped = (o.flags & kFeedforwardClamped) != 0;
    double hand_err = 0.0, peak_hand_err = 0.0;
    for (int k = 0; k < 500; ++k) {
      const TickOutput& p = c.tick(in);
      REQUIRE(all_finite(p));
      CHECK((p.flags & kReferenceJump) == 0);
      clamped = clamped || (p.flags & kFeedforwardClamped) != 0;
      worst = std::max(worst, worst_limit_ratio(p.tau_ff));
      asked = std::max(asked, worst_limit_ratio(p.tau_a));
      hand_err = (com_of(p, Bone::RightHand) - hand_ref).norm();
      peak_hand_err = std::max(peak_hand_err, hand_err);
    }
    const std::string what = detect ? "with" : "without";
    MESSAGE(what << " jump detection: largest |tau_ff| / limit " << worst << " (A's |tau| / limit " << asked
                 << "), right hand 0.5 s later " << hand_err * 1e3 << " mm (peak " << peak_hand_err * 1e3 << " mm)");
    if (detect) {
      CHECK(jumped);
      CHECK(c.stats().reference_jumps == 1);
      CHECK_FALSE(clamped);
      CHECK(worst < 0.5);
      CHECK(hand_err < 0.02);
      CHECK(peak_hand_err < 0.02);
      worst_with = worst;
      asked_with = asked;
    } else {
      CHECK_FALSE(jumped);
      CHECK(c.stats().reference_jumps == 0);
      CHECK(clamped);               // A's stiff drives ask for more than B's torque limits ...
      CHECK(worst <= 1.0 + 1e-12);  // ... and what B is fed stays bounded by them
      worst_without = worst;
      asked_without = asked;
      CHECK(peak_hand_err > 0.1);
    }
  }
  CHECK(worst_without > 2.0 * worst_with);
  CHECK(asked_without > 10.0 * asked_with);
}

TEST_CASE("PD + feedforward holds a pose with the forearm forward far better than PD alone at the same gains") {
  const ReferencePose held = arms_lowered(1.2, 1.5);
  const sim::Vec3 hand_ref = com_of(held.qpos, Bone::RightHand);
  double err[2] = {0.0, 0.0};
  for (const Feedforward f : {Feedforward::simulation, Feedforward::none}) {
    AvatarConfig cfg;
    cfg.feedforward = f;
    AvatarController c = make_controller(cfg);
    TickInput in;
    in.reference = held;
    for (int k = 0; k < 1500; ++k) REQUIRE(all_finite(c.tick(in)));
    err[f == Feedforward::none ? 1 : 0] = (com_of(c.output(), Bone::RightHand) - hand_ref).norm();
    if (f == Feedforward::none) {
      for (size_t d = 0; d < static_cast<size_t>(humanoid().nv); ++d) CHECK(c.output().tau_ff[d] == 0.0);
    }
  }
  MESSAGE("right hand error after 1.5 s at stiffness 0.5: PD+FF " << err[0] * 1e3 << " mm, PD only " << err[1] * 1e3
                                                                  << " mm");
  CHECK(err[0] < 1e-3);
  CHECK(err[1] > 5e-3);
}

TEST_CASE("inverse-dynamics variant: warm-up, the delayed reference tracked, tau_ff = RNEA of the exact reference") {
  AvatarConfig cfg;
  cfg.feedforward = Feedforward::inverse_dynamics;
  AvatarController c = make_controller(cfg);
  const int lag = cfg.id_lag_ticks;
  const double dt = humanoid().timestep_s;
  const size_t elbow_q = qpos_of(Bone::RightLowerArm);
  const size_t elbow_v = dof_of(Bone::RightLowerArm);
  constexpr double kW = 2.0 * M_PI;  // 1 Hz
  const auto angle = [&](double t) { return 1.0 + 0.5 * std::sin(kW * t); };
  TickInput in;
  in.reference = arms_lowered(1.2, 1.0);
  in.reference.has_velocity = false;

  auto scratch = sim::make_data(humanoid());
  std::array<double, sim::kMaxDofs> qacc{}, tau{};
  int warming = 0, last_warming = -1;
  double worst_track = 0.0, worst_tau = 0.0, tau_amp = 0.0, worst_delay = 0.0, worst_undelayed = 0.0;
  for (int k = 0; k < 2000; ++k) {
    in.reference.qpos[elbow_q] = angle(k * dt);
    const TickOutput& o = c.tick(in);
    REQUIRE(all_finite(o));
    CHECK((o.flags & (kReferenceJump | kResetB)) == 0);
    if ((o.flags & kWarmingUp) != 0) {
      ++warming;
      last_warming = k;
    }
    if (k < 1000) continue;  // B settles on the delayed reference after warm-up
    const double td = (k - lag) * dt;
    worst_delay = std::max(worst_delay, std::abs(o.reference_qpos[elbow_q] - angle(td)));
    worst_track = std::max(worst_track, std::abs(o.qpos[elbow_q] - o.reference_qpos[elbow_q]));
    worst_undelayed = std::max(worst_undelayed, std::abs(o.qpos[elbow_q] - in.reference.qpos[elbow_q]));
    // RNEA of the exact reference at the delayed time, computed here.
    std::copy_n(in.reference.qpos.begin(), humanoid().nq, scratch->qpos.begin());
    scratch->qpos[elbow_q] = angle(td);
    scratch->qvel.fill(0.0);
    scratch->qvel[elbow_v] = 0.5 * kW * std::cos(kW * td);
    qacc[elbow_v] = -0.5 * kW * kW * std::sin(kW * td);
    sim::forward_kinematics(humanoid(), *scratch);
    sim::inverse_dynamics(humanoid(), *scratch, qacc, tau);
    tau_amp = std::max(tau_amp, std::abs(tau[elbow_v]));
    worst_tau = std::max(worst_tau, std::abs(o.tau_ff[elbow_v] - tau[elbow_v]));
  }
  MESSAGE("inverse dynamics: warming up for " << warming << " ticks (lag " << lag << "); elbow tracking error "
                                              << worst_track << " rad (to the undelayed one " << worst_undelayed
                                              << " rad); tau_ff vs exact RNEA " << worst_tau << " of " << tau_amp
                                              << " N*m");
  CHECK(warming == last_warming + 1);  // only at the start
  CHECK(warming >= lag);
  CHECK(warming <= lag + 2);
  CHECK(worst_delay < 1e-12);  // the reference followed is exactly `lag` ticks old
  CHECK(worst_track < 0.01);
  CHECK(worst_undelayed > 0.1);  // B follows the delayed reference, not this tick's
  CHECK(tau_amp > 0.5);
  CHECK(worst_tau < 0.03 * tau_amp);
}

TEST_CASE("free_servo root held 1 m above the ground: the servo carries the body's weight") {
  AvatarConfig cfg;
  cfg.root = RootControl::free_servo;
  AvatarController c = make_controller(cfg);
  TickInput in;
  in.reference = rest_reference(humanoid());
  in.reference.qpos[2] += 1.0;
  double worst_root = 0.0;
  for (int k = 0; k < 1500; ++k) {
    const TickOutput& o = c.tick(in);
    REQUIRE(all_finite(o));
    CHECK(o.nevents == 0);
    if (k > 500) {
      worst_root = std::max(worst_root, (sim::Vec3(o.qpos[0], o.qpos[1], o.qpos[2]) -
                                         sim::Vec3(in.reference.qpos[0], in.reference.qpos[1], in.reference.qpos[2]))
                                            .norm());
    }
  }
  const sim::Model& m = humanoid();
  const double weight = m.total_mass_kg() * -m.gravity.z();
  const sim::Vec3 f = c.output().root_force;
  MESSAGE("free root: servo force " << f.transpose() << " N for a weight of " << weight << " N; root within "
                                    << worst_root * 1e3 << " mm");
  CHECK(c.sim_b().root_mode == sim::RootMode::free);
  CHECK(f.z() == doctest::Approx(weight).epsilon(0.03));
  CHECK(std::hypot(f.x(), f.y()) < 0.03 * weight);
  // Closed form: the servo's spring sags by g / w^2 under the weight (the joints at rest).
  const double w = 2.0 * M_PI * cfg.root_servo_hz;
  const double sag = in.reference.qpos[2] - c.output().qpos[2];
  CHECK(sag == doctest::Approx(-m.gravity.z() / (w * w)).epsilon(0.05));
  CHECK(worst_root < 0.01);
  for (const Bone foot : {Bone::LeftFoot, Bone::RightFoot}) CHECK(c.output().bones[sim::index(foot)].pos.z() > 0.9);
}
