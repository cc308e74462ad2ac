// Unplug and replug: the simulated band killed and started again, and the
// band rebooting on a `reset` command; the link resumes on its own.
#include <doctest/doctest.h>

#include <filesystem>
#include <memory>
#include <set>

#include "sim_process.hpp"
#include "tonus/host/transport/reconnecting_link.hpp"
#include "tonus/protocol/payloads.hpp"

using namespace tonus;
using namespace std::chrono_literals;
using Kind = host::LinkEvent::Kind;

namespace {

std::string socket_path(const char* what) {
  return (std::filesystem::temp_directory_path() /
          (std::string("tonus-") + what + "-" + std::to_string(::getpid()) + ".sock"))
      .string();
}

std::vector<std::string> band_args(const std::string& path, const char* seconds, const std::string& storage) {
  return {"--synthetic", "rest", "--seconds", seconds, "--quiet", "--hid-socket", path, "--storage", storage};
}

}  // namespace

TEST_CASE("unplug/replug: tonus-band-sim killed and restarted, the link resumes by itself") {
  const std::string path = socket_path("replug");
  // The band's flash outlives the unplug: its boot count, and so its epoch, moves on.
  const std::string storage = socket_path("replug-flash") + ".bin";
  std::filesystem::remove(storage);
  auto sim = std::make_unique<test::SimProcess>(band_args(path, "20", storage));
  REQUIRE(sim->started());
  host::ReconnectPolicy policy;
  policy.first_retry = 20ms;
  policy.max_retry = 200ms;
  policy.stale_after = 1000ms;
  host::ReconnectingBandLink link(host::seqpacket_hid_opener(path), policy);

  std::uint64_t before = 0, after = 0, disconnects = 0, reconnects = 0, restarted = 0;
  std::set<std::uint8_t> epochs;
  bool killed = false, restarted_band = false;
  std::chrono::steady_clock::time_point killed_at{};
  const auto deadline = std::chrono::steady_clock::now() + 20s;  // the test stops by itself
  while (after < 500 && std::chrono::steady_clock::now() < deadline) {
    const host::LinkEvent e = link.poll(50);
    REQUIRE(e.kind != Kind::closed);  // a reconnecting link never gives up
    if (e.kind == Kind::reconnected) ++reconnects;
    if (e.kind == Kind::disconnected) ++disconnects;
    if (e.kind == Kind::stream) {
      epochs.insert(e.stream.boot_epoch);
      CHECK(e.stream.boot_epoch != 0);
      if (e.restarted) ++restarted;
      (restarted_band ? after : before) += 1;
    }
    if (!killed && before >= 500) {
      sim.reset();  // SIGKILL: the band vanishes mid-stream, its socket file stays behind
      killed = true;
      killed_at = std::chrono::steady_clock::now();
    }
    if (killed && !restarted_band && std::chrono::steady_clock::now() - killed_at > 300ms) {
      sim = std::make_unique<test::SimProcess>(band_args(path, "20", storage));  // plugged in again
      REQUIRE(sim->started());
      restarted_band = true;
    }
  }
  CHECK(after >= 500);
  CHECK(disconnects == 1);
  CHECK(reconnects == 2);            // the first connection and the one after the replug
  CHECK(link.open_failures() >= 1);  // it retried while the band was away
  CHECK(epochs.size() == 2);         // two boots, told apart by their epochs
  CHECK(restarted == 1);
  const host::LinkStats s = link.stats();
  CHECK(s.restarts == 1);
  CHECK(s.reconnects == 1);
  CHECK(s.disconnects == 1);
  CHECK(s.stale + s.duplicates == 0);
  CHECK(s.decode_errors == 0);
  std::filesystem::remove(path);
  std::filesystem::remove(storage);
}

TEST_CASE("the band reboots on `reset` after 500 reports: every report of its next boot is kept (defect 8)") {
  test::SimProcess sim({"--synthetic", "rest", "--seconds", "4", "--fast", "--quiet", "--hid-fd", "3"});
  REQUIRE(sim.started());
  host::SeqpacketHidTransport transport(sim.take_hid());
  host::HidBandLink link(transport);
  std::uint64_t first_boot = 0, second_boot = 0, restarted = 0;
  std::uint8_t epoch = 0;
  std::uint32_t last_time_first_boot_us = 0, first_time_second_boot_us = 0;
  const auto count = [&](const proto::StreamMessage& m) {
    if (epoch == 0) epoch = m.boot_epoch;
    const bool first = m.boot_epoch == epoch;
    if (first) last_time_first_boot_us = m.device_time_us;
    if (!first && second_boot == 0) first_time_second_boot_us = m.device_time_us;
    (first ? first_boot : second_boot) += 1;
  };
  const auto info_rsp = link.transact(proto::make_request(proto::Opcode::get_device_info, 1), 2000, count);
  REQUIRE(info_rsp.has_value());
  proto::DeviceInfo info{};
  REQUIRE(proto::read_payload(*info_rsp, info) == proto::Error::ok);
  const double expected = 4.0 * info.report_rate_hz;  // reports in the run
  bool reset_sent = false;
  for (;;) {
    const host::LinkEvent e = link.poll(3000);
    if (e.kind == Kind::closed || e.kind == Kind::none) break;
    if (e.kind != Kind::stream) continue;
    if (e.restarted) ++restarted;
    count(e.stream);
    if (!reset_sent && first_boot >= 500) {
      reset_sent = true;
      proto::Request req{};
      REQUIRE(proto::make_request(proto::Opcode::reset, 2, proto::ResetRequest{proto::ResetKind::reboot}, req) ==
              proto::Error::ok);
      const auto rsp = link.transact(req, 2000, count);
      REQUIRE(rsp.has_value());
      CHECK(rsp->status == proto::Status::ok);
    }
  }
  REQUIRE(reset_sent);
  // The band numbers from 0 again after the reset, well within 4096 reports: none may be dropped.
  const host::LinkStats s = link.stats();
  MESSAGE("first boot " << first_boot << " reports, second boot " << second_boot << ", of " << expected);
  CHECK(first_boot + second_boot == s.delivered);
  CHECK(static_cast<double>(first_boot + second_boot) >= 0.97 * expected);  // less the reboot's own gap
  CHECK(static_cast<double>(second_boot) >= 0.97 * expected - static_cast<double>(first_boot));
  CHECK(restarted == 1);
  CHECK(s.restarts == 1);
  // Like the band's SysTick count, the simulated device clock starts again at the reboot.
  CHECK(last_time_first_boot_us >= 900000U);
  CHECK(first_time_second_boot_us < 50000U);
  CHECK(s.stale + s.duplicates + s.late == 0);
  CHECK(sim.wait(5s) == 0);
}
