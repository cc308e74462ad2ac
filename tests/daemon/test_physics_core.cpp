// The physics core tick by tick (no threads, no clock): band reports set the
// stiffness, a cube dropped on the hand is reacted to less when stiffer, and
// commands, staleness and events behave.
#include <doctest/doctest.h>

#include "daemon_fixtures.hpp"
#include "tonus/host/daemon/physics_core.hpp"

using namespace tonus;
using namespace tonus::daemon;

namespace {

// Runs the core at 1 kHz from t = 1 s with band reports at `level` every 2 ms,
// drops a 1 kg cube on the right hand at 1.5 s, and returns its reaction.
Event cube_reaction(double level) {
  std::string error;
  PhysicsCoreConfig cfg;
  cfg.avatar.stiffness.max_rate_per_s = 10.0;
  auto core = PhysicsCore::create(test::daemon_humanoid(), cfg, error);
  REQUIRE(core);
  Event reaction;
  bool got = false;
  for (int k = 0; k < 4000 && !got; ++k) {
    const std::int64_t now = 1'000'000 + k * 1000;
    if (k % 2 == 0) {
      BandSample s;
      s.arrival_us = now;
      s.levels.fill(level);
      REQUIRE(core->push_band(s));
    }
    if (k == 500) {
      Command c;
      c.kind = Command::Kind::gift;
      c.id = 42;
      c.gift = GiftKind::cube;
      REQUIRE(core->push_command(c));
    }
    core->tick(now);
    Event e;
    while (core->events().try_dequeue(e)) {
      if (e.kind == Event::Kind::gift_reaction) {
        reaction = e;
        got = true;
      }
    }
  }
  REQUIRE(got);
  return reaction;
}

}  // namespace

TEST_CASE("physics core: a stiffer performer's hand gives less under the same cube") {
  const Event soft = cube_reaction(0.1);
  const Event stiff = cube_reaction(0.9);
  MESSAGE("1 kg cube on the right hand: peak deflection " << soft.peak_deflection_m * 1e3 << " mm at stiffness "
                                                          << soft.stiffness << ", " << stiff.peak_deflection_m * 1e3
                                                          << " mm at " << stiff.stiffness);
  CHECK(soft.id == 42);
  CHECK(soft.bone == sim::Bone::RightHand);
  CHECK(soft.stiffness == doctest::Approx(0.1).epsilon(0.01));
  CHECK(stiff.stiffness == doctest::Approx(0.9).epsilon(0.01));
  CHECK(soft.peak_deflection_m > 0.005);  // the cube was felt
  CHECK(stiff.peak_deflection_m < 0.7 * soft.peak_deflection_m);
}

TEST_CASE("physics core: band silence relaxes to the safe default, an override wins until released") {
  std::string error;
  PhysicsCoreConfig cfg;
  cfg.avatar.stiffness.max_rate_per_s = 10.0;
  auto core = PhysicsCore::create(test::daemon_humanoid(), cfg, error);
  REQUIRE(core);
  Snapshot snap;
  const auto run_to = [&](std::int64_t from, std::int64_t to, bool band, double level) {
    for (std::int64_t t = from; t < to; t += 1000) {
      if (band) {
        BandSample s;
        s.arrival_us = t;
        s.levels.fill(level);
        core->push_band(s);
      }
      core->tick(t);
    }
    REQUIRE(core->snapshots().update());
    snap = core->snapshots().read_slot();
  };
  run_to(0, 500'000, true, 0.9);
  CHECK(snap.stiffness[0] == doctest::Approx(0.9));
  CHECK(snap.band_live);
  // The band goes silent at 0.5 s: still 0.9 at 0.6 s, the safe default by 0.7 s.
  run_to(500'000, 600'000, false, 0);
  CHECK(snap.stiffness[0] == doctest::Approx(0.9));
  run_to(600'000, 700'000, false, 0);
  CHECK(snap.stiffness[2] == doctest::Approx(cfg.stiffness.safe_default[2]));
  CHECK_FALSE(snap.band_live);
  // Back.
  run_to(700'000, 900'000, true, 0.8);
  CHECK(snap.stiffness[1] == doctest::Approx(0.8));
  // Override, then release.
  Command c;
  c.kind = Command::Kind::stiffness_override;
  c.levels = {1.0, 0.0, 0.5, 2.0};
  core->push_command(c);
  run_to(900'000, 1'200'000, true, 0.8);
  CHECK(snap.override_active);
  CHECK(snap.stiffness[0] == doctest::Approx(1.0));
  CHECK(snap.stiffness[1] == doctest::Approx(0.0));
  CHECK(snap.stiffness[3] == doctest::Approx(1.0));  // clamped
  c.kind = Command::Kind::stiffness_release;
  core->push_command(c);
  run_to(1'200'000, 1'500'000, true, 0.8);
  CHECK_FALSE(snap.override_active);
  CHECK(snap.stiffness[0] == doctest::Approx(0.8));
  Event e;
  int stale = 0, live = 0;
  while (core->events().try_dequeue(e)) {
    stale += e.kind == Event::Kind::band_stale ? 1 : 0;
    live += e.kind == Event::Kind::band_live ? 1 : 0;
  }
  CHECK(stale == 1);
  CHECK(live == 2);
}

TEST_CASE("physics core: gifts show in the snapshot, a full scene refuses with an event, clear empties it") {
  std::string error;
  auto core = PhysicsCore::create(test::daemon_humanoid(), PhysicsCoreConfig{}, error);
  REQUIRE(core);
  Command c;
  c.kind = Command::Kind::gift;
  c.gift = GiftKind::ball;
  // In batches: the command queue holds fewer than kMaxObjects.
  std::int64_t now_us = 0;
  for (std::uint32_t i = 0; i < sim::kMaxObjects + 2; ++i) {
    c.id = i;
    core->push_command(c);
    if (i % 32 == 31) core->tick(now_us += 1000);
  }
  core->tick(now_us += 1000);
  REQUIRE(core->snapshots().update());
  const Snapshot& s = core->snapshots().read_slot();
  CHECK(s.nobjects == static_cast<int>(sim::kMaxObjects));
  CHECK(s.objects[0].kind == GiftKind::ball);
  CHECK(s.objects[0].size_m == doctest::Approx(0.11));
  int spawned = 0, refused = 0;
  Event e;
  while (core->events().try_dequeue(e)) {
    spawned += e.kind == Event::Kind::gift_spawned ? 1 : 0;
    if (e.kind == Event::Kind::gift_refused) {
      ++refused;
      CHECK(e.error == avatar::GiftError::full);
    }
  }
  CHECK(spawned == static_cast<int>(sim::kMaxObjects));
  CHECK(refused == 2);
  c.kind = Command::Kind::clear_gifts;
  core->push_command(c);
  core->tick(now_us += 1000);
  REQUIRE(core->snapshots().update());
  CHECK(core->snapshots().read_slot().nobjects == 0);
}
