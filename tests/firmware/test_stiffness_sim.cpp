// The step-to-level latency as outside checks and a host see it: tonus-band-sim
// run as a child, its JSON (device time), and its HID and CAN links decoded on
// the host (arrival time on the host's clock).
#include <doctest/doctest.h>
#include <poll.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "summary.hpp"
#include "support/read_file.hpp"
#include "tonus/protocol/can.hpp"
#include "tonus/protocol/hid.hpp"
#include "tonus/protocol/payloads.hpp"
#include "tonus/protocol/sequence.hpp"

extern char** environ;

using namespace tonus;

namespace {

// Runs the sim with `args`; fd 3 and 4 of the child are the given fds (or none).
pid_t spawn_sim(std::vector<std::string> args, int hid_fd = -1, int can_fd = -1) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  if (hid_fd >= 0) posix_spawn_file_actions_adddup2(&fa, hid_fd, 3);
  if (can_fd >= 0) posix_spawn_file_actions_adddup2(&fa, can_fd, 4);
  static char program[] = TONUS_BAND_SIM;
  std::vector<char*> argv{program};
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  if (posix_spawn(&pid, TONUS_BAND_SIM, &fa, nullptr, argv.data(), environ) != 0) pid = -1;
  posix_spawn_file_actions_destroy(&fa);
  return pid;
}

int wait_exit(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The number after "key": in a flat JSON text, or -1 (absent or null).
double json_number(const std::string& text, const std::string& key) {
  const auto at = text.find("\"" + key + "\":");
  if (at == std::string::npos) return -1.0;
  std::istringstream in(text.substr(at + key.size() + 3));
  double v = -1.0;
  if (!(in >> v)) return -1.0;
  return v;
}

std::uint64_t host_now_us() {
  return static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
          .count());
}

// A stream seen by the host: device times (unwrapped) and arrival times on the
// same axis (the sim's device clock is the host's CLOCK_MONOTONIC: --clock-offset-us 0).
struct Seen {
  proto::TimestampUnwrapper unwrap;
  std::vector<std::uint64_t> device_us, arrival_us;
  std::vector<std::array<std::uint16_t, fw::kGroups>> levels;
  void add(const proto::StreamMessage& m, std::uint64_t host_us) {
    const auto dev = static_cast<std::uint64_t>(unwrap.push(m.device_time_us));
    // Same 32-bit clock domain: the difference is the transport delay.
    const auto delay = static_cast<std::int32_t>(static_cast<std::uint32_t>(host_us) - m.device_time_us);
    device_us.push_back(dev);
    arrival_us.push_back(static_cast<std::uint64_t>(static_cast<std::int64_t>(dev) + delay));
    levels.push_back({m.levels[0], m.levels[1], m.levels[2], m.levels[3]});
  }
  [[nodiscard]] double delay_percentile_ms(double p) const {
    std::vector<double> d;
    for (std::size_t k = 0; k < device_us.size(); ++k) {
      d.push_back(static_cast<double>(static_cast<std::int64_t>(arrival_us[k] - device_us[k])) * 1e-3);
    }
    std::sort(d.begin(), d.end());
    return d.empty() ? -1.0 : d[static_cast<std::size_t>(p * static_cast<double>(d.size() - 1))];
  }
};

}  // namespace

TEST_CASE("tonus-band-sim --synthetic step writes the step-to-level latency, 90 % within 60 ms") {
  const std::string json = "/tmp/tonus-stiffness-" + std::to_string(::getpid()) + ".json";
  const pid_t pid = spawn_sim({"--synthetic", "step", "--seconds", "2", "--fast", "--quiet", "--json", json});
  REQUIRE(pid > 0);
  REQUIRE(wait_exit(pid) == 0);
  const std::string text = test::read_file(json);
  ::unlink(json.c_str());
  const double l10 = json_number(text, "level_latency_10_ms"), l50 = json_number(text, "level_latency_50_ms"),
               l90 = json_number(text, "level_latency_90_ms");
  MESSAGE("tonus-band-sim --synthetic step --seconds 2 --fast: level latency 10/50/90 % " << l10 << " / " << l50
                                                                                          << " / " << l90 << " ms");
  CHECK(l10 >= 0.0);
  CHECK(l10 <= l50);
  CHECK(l50 <= l90);
  CHECK(l90 <= 60.0);
  // Another scenario has no step: the fields are null.
  const pid_t rest = spawn_sim({"--synthetic", "rest", "--seconds", "0.5", "--fast", "--quiet", "--json", json});
  REQUIRE(wait_exit(rest) == 0);
  const std::string text2 = test::read_file(json);
  ::unlink(json.c_str());
  CHECK(text2.find("\"level_latency_90_ms\": null") != std::string::npos);
}

TEST_CASE("step to level on the host, over HID and over CAN (real time, the sim's links)") {
  std::array<int, 2> hid{-1, -1}, can{-1, -1};
  REQUIRE(::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, hid.data()) == 0);
  REQUIRE(::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, can.data()) == 0);
  // In real time the sim drops what the host does not read in time, as a band must. A CAN message is several
  // frames, so the default send buffer holds only ~100 ms of them: a loaded CI box that parks this reader that
  // long lost a tenth of the messages. A larger buffer (capped by net.core.wmem_max) keeps the measurement whole.
  for (const int fd : {hid[1], can[1]}) {
    const int bytes = 2 << 20;
    ::setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &bytes, sizeof bytes);
  }
  // Real time, and the device clock = the host's CLOCK_MONOTONIC, so arrival - device time is the link delay.
  const pid_t pid = spawn_sim(
      {"--synthetic", "step", "--seconds", "2", "--quiet", "--clock-offset-us", "0", "--hid-fd", "3", "--can-fd", "4"},
      hid[1], can[1]);
  ::close(hid[1]);
  ::close(can[1]);
  REQUIRE(pid > 0);

  Seen over_hid, over_can;
  proto::can::StreamAssembler assembler(proto::DeviceConfig{}.can_node_id);
  std::array<pollfd, 2> fds{{{hid[0], POLLIN, 0}, {can[0], POLLIN, 0}}};
  int open_links = 2;
  while (open_links > 0) {
    if (::poll(fds.data(), fds.size(), 5000) <= 0) break;
    for (std::size_t i = 0; i < fds.size(); ++i) {
      if ((fds[i].revents & (POLLIN | POLLHUP)) == 0) continue;
      std::array<std::uint8_t, 128> buf{};
      const ssize_t n = ::recv(fds[i].fd, buf.data(), buf.size(), 0);
      const std::uint64_t now = host_now_us();
      if (n <= 0) {
        fds[i].fd = -1;
        --open_links;
        continue;
      }
      if (i == 0) {
        proto::StreamMessage m{};
        if (proto::hid::unpack_stream(std::span(buf.data(), static_cast<std::size_t>(n)), m) == proto::Error::ok) {
          over_hid.add(m, now);
        }
      } else if (static_cast<std::size_t>(n) == 16) {  // struct can_frame
        proto::CanFrame f{};
        std::uint32_t id = 0;
        std::copy_n(buf.data(), 4, reinterpret_cast<std::uint8_t*>(&id));
        f.id = id & 0x1FFFFFFFU;
        if ((id & 0x80000000U) != 0) f.flags |= proto::CanFrame::kExtended;
        f.dlc = std::min<std::uint8_t>(buf[4], 8);
        std::copy_n(buf.data() + 8, f.dlc, f.data.data());
        bool complete = false;
        if (assembler.push(f, complete) == proto::Error::ok && complete) over_can.add(assembler.message(), now);
      }
    }
  }
  ::close(hid[0]);
  ::close(can[0]);
  REQUIRE(wait_exit(pid) == 0);
  // 2 s at 500 reports/s: 1000 sent; a few may still be dropped when this reader is parked for long.
  MESSAGE("received " << over_hid.device_us.size() << " reports over HID, " << over_can.device_us.size()
                      << " over CAN, of 1000");
  REQUIRE(over_hid.device_us.size() > 900);
  REQUIRE(over_can.device_us.size() > 900);

  for (Seen* seen : {&over_hid, &over_can}) {
    const std::string link = seen == &over_hid ? "HID" : "CAN";
    INFO(link);
    // The step frame from the first report, as the sim does (2 kHz, 500 Hz reports).
    const std::uint64_t step_us = sim::frame_time_us(seen->device_us.front(), 2000, 2000, 500);
    const sim::StepLatency device = sim::step_latency(seen->device_us, seen->levels, step_us);
    const sim::StepLatency host = sim::step_latency(seen->arrival_us, seen->levels, step_us);
    MESSAGE(link << ": step to level, device time 10/50/90 % " << device.ms10 << " / " << device.ms50 << " / "
                 << device.ms90 << " ms; on the host " << host.ms10 << " / " << host.ms50 << " / " << host.ms90
                 << " ms; link delay p50 " << seen->delay_percentile_ms(0.5) << " ms, p99 "
                 << seen->delay_percentile_ms(0.99) << " ms");
    CHECK(device.ms90 >= 0.0);
    CHECK(device.ms90 <= 60.0);
    // The sim hands a 1 ms block over when it starts (a band when it ends), so a
    // report can leave up to a block before its last sample's time stamp.
    CHECK(host.ms90 >= device.ms90 - 1.0);
    CHECK(host.ms90 <= device.ms90 + 20.0);  // a 2-core CI box: the link adds well under a frame of 20 ms
  }
}
