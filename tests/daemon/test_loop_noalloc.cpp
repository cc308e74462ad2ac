// The whole physics loop allocates nothing: the paced thread ticking the core
// (band reports, tracker poses, gifts and overrides in; snapshots and events
// out) runs two seconds under the allocation counter while this thread feeds
// its queues and reads its outputs as the other threads would.
#include <doctest/doctest.h>

#include <unistd.h>

#include <chrono>
#include <thread>

#include "daemon_fixtures.hpp"
#include "support/allocation_counter.hpp"
#include "tonus/host/daemon/physics_thread.hpp"
#include "tonus/host/daemon/recorder.hpp"
#include "tonus/host/transport/host_clock.hpp"

using namespace tonus;
using namespace tonus::daemon;

TEST_CASE("the physics loop allocates nothing: 2 s at 1 kHz with band, tracker, gifts, overrides and recording") {
  REQUIRE(test::probe_allocation_counter() == 2);
  std::string error;
  PhysicsCoreConfig cfg;
  cfg.viewer_every_ticks = 10;  // the viewer's snapshots too
  auto core = PhysicsCore::create(test::daemon_humanoid(), cfg, error);
  REQUIRE(core);
  PacingConfig pace;
  pace.realtime_priority = 0;
  pace.lock_memory = false;
  PhysicsThread thread(*core, pace);
  // Recording too: the loop's side of it is a copy into preallocated queues.
  // The writer thread (which allocates its chunks) starts after counting.
  recording::Header header;
  header.nq = test::daemon_humanoid().nq;
  const std::string record_path = "/tmp/tonus-noalloc-" + std::to_string(::getpid()) + ".tonusrec";
  auto recorder = Recorder::create(record_path, header, error);
  REQUIRE(recorder);
  core->set_recorder(recorder.get());
  // Everything the loop and this feeder need, made before counting.
  PoseSample pose;
  pose.qpos = test::daemon_humanoid().qpos0;
  BandSample band;
  Command gift;
  gift.kind = Command::Kind::gift;
  Command override_cmd;
  override_cmd.kind = Command::Kind::stiffness_override;
  override_cmd.levels = {0.9, 0.9, 0.9, 0.9};
  Command release;
  release.kind = Command::Kind::stiffness_release;
  Event ev;
  thread.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // warm: first ticks, first events

  test::start_counting_allocations();
  const auto t0 = std::chrono::steady_clock::now();
  int k = 0;
  std::uint64_t events = 0, snapshots = 0;
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(2)) {
    const std::int64_t now = host::steady_now_us();
    band.arrival_us = now;
    band.sampled_host_us = now - 3000;
    band.levels.fill((k % 100) / 100.0);
    core->push_band(band);
    if (k % 4 == 0) {  // a 125 Hz tracker swinging the root sideways
      pose.t_us = now;
      pose.qpos[1] = 0.1 * std::sin(k * 0.01);
      core->push_pose(pose);
    }
    if (k % 250 == 0) {
      gift.gift = (k / 250) % 2 == 0 ? GiftKind::cube : GiftKind::ball;
      core->push_command(gift);
    }
    if (k == 700) core->push_command(override_cmd);
    if (k == 1400) core->push_command(release);
    while (core->events().try_dequeue(ev)) ++events;
    snapshots += core->snapshots().update() ? 1U : 0U;
    ++k;
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  const long allocations = test::stop_counting_allocations();
  thread.request_interval();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  IntervalFigures f;
  const bool got_interval = thread.take_interval(f);
  thread.stop();
  recorder->start();
  recorder->stop();
  const RecorderStatus rs = recorder->status();
  ::unlink(record_path.c_str());
  MESSAGE(rs.ticks << " ticks recorded in " << rs.chunks << " chunks" << (rs.error.empty() ? "" : ": ") << rs.error);
  CHECK(rs.error.empty());
  CHECK(rs.ticks == thread.ticks());
  MESSAGE(thread.ticks() << " ticks, " << events << " events, " << snapshots << " snapshots read, "
                         << core->stats().band_samples << " band reports, " << core->stats().pose_samples
                         << " poses: " << allocations << " allocations");
  CHECK(allocations == 0);
  CHECK(thread.ticks() > 1500);
  CHECK(core->stats().commands >= 9);
  CHECK(events > 8);
  CHECK(got_interval);
}
