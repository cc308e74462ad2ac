// The SocketCAN path without a CAN interface (vcan needs privileges CI lacks):
// the same socket code on a socketpair carrying struct can_frame.
#include <doctest/doctest.h>

#include <linux/can/error.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>

#include "tonus/host/transport/band_link.hpp"

using namespace tonus;

namespace {

struct Pair {
  int ours = -1, theirs = -1;
  Pair() {
    int fds[2] = {-1, -1};
    REQUIRE(::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds) == 0);
    ours = fds[0];
    theirs = fds[1];
  }
  ~Pair() {
    if (theirs >= 0) ::close(theirs);
  }
  Pair(const Pair&) = delete;
  Pair& operator=(const Pair&) = delete;
  void send(const can_frame& f) const { REQUIRE(::send(theirs, &f, sizeof f, 0) == static_cast<ssize_t>(sizeof f)); }
};

can_frame frame(canid_t id, std::uint8_t len) {
  can_frame f{};
  f.can_id = id;
  f.len = len;
  for (std::uint8_t k = 0; k < len; ++k) f.data[k] = k;
  return f;
}

}  // namespace

TEST_CASE("SocketCAN: every option's setsockopt result is checked") {
  // A Unix socket has no CAN_RAW options: the first one must be refused and named.
  Pair p;
  std::string error;
  CHECK_FALSE(host::configure_can_socket(p.ours, 1, error));
  CHECK(error.find("CAN_RAW_FILTER") != std::string::npos);
  ::close(p.ours);
  // A closed descriptor cannot even take SO_TIMESTAMP: adopt refuses it.
  error.clear();
  CHECK(host::SocketCanTransport::adopt(p.ours, error) == nullptr);
  CHECK(error.find("SO_TIMESTAMP") != std::string::npos);
}

TEST_CASE("SocketCAN: error frames are consumed and show bus-off, frames carry kernel receive times") {
  Pair p;
  std::string error;
  auto t = host::SocketCanTransport::adopt(p.ours, error);
  REQUIRE_MESSAGE(t != nullptr, error);

  const std::int64_t before = host::steady_now_us();
  p.send(frame(0x101, 8));
  p.send(frame(CAN_ERR_FLAG | CAN_ERR_CRTL, CAN_ERR_DLC));
  p.send(frame(CAN_ERR_FLAG | CAN_ERR_BUSOFF, CAN_ERR_DLC));
  p.send(frame(0x121, 4));
  ::usleep(20000);  // the frames wait in the socket: their kernel time is older than the read
  proto::CanFrame f{};
  REQUIRE(t->read(f, 100) == 1);
  CHECK(f.id == 0x101);
  const std::int64_t stamped = t->last_rx_host_us();
  const std::int64_t read_at = host::steady_now_us();
  CHECK(stamped >= before - 2000);  // realtime -> steady conversion is good to well under 2 ms
  CHECK(stamped <= read_at - 15000);
  REQUIRE(t->read(f, 100) == 1);  // the two error frames in between are not returned
  CHECK(f.id == 0x121);
  CHECK(f.dlc == 4);
  CHECK(t->bus_status().error_frames == 2);
  CHECK(t->bus_status().controller_problems == 1);
  CHECK(t->bus_status().bus_off);
  CHECK(t->bus_status().bus_off_events == 1);
  p.send(frame(CAN_ERR_FLAG | CAN_ERR_RESTARTED, CAN_ERR_DLC));
  CHECK(t->read(f, 20) == 0);  // only an error frame: a timeout for the caller
  CHECK_FALSE(t->bus_status().bus_off);
  CHECK(t->bus_status().restarts == 1);

  // The peer goes away: the link is gone.
  ::close(p.theirs);
  p.theirs = -1;
  CHECK(t->read(f, 100) == -1);
  CHECK_FALSE(t->error().empty());
}

TEST_CASE("SocketCAN: a full transmit queue (ENOBUFS) is retried, then given up and counted") {
  Pair p;
  std::string error;
  auto t = host::SocketCanTransport::adopt(p.ours, error);
  REQUIRE(t != nullptr);
  int full_for = 3;
  int calls = 0;
  t->set_writer([&](int fd, const void* data, std::size_t size) -> long {
    ++calls;
    if (full_for-- > 0) {
      errno = ENOBUFS;
      return -1;
    }
    return static_cast<long>(::send(fd, data, size, 0));
  });
  proto::CanFrame f{};
  f.id = 0x601;
  f.dlc = 2;
  CHECK(t->write(f));
  CHECK(calls == 4);
  CHECK(t->bus_status().tx_retries == 3);
  can_frame got{};
  CHECK(::recv(p.theirs, &got, sizeof got, 0) == static_cast<ssize_t>(sizeof got));
  CHECK(got.can_id == 0x601);

  full_for = 1000;  // never drains
  CHECK_FALSE(t->write(f));
  CHECK(t->bus_status().tx_dropped == 1);
  CHECK(t->error().find("ENOBUFS") != std::string::npos);

  full_for = 0;
  t->set_writer([](int, const void*, std::size_t) -> long {
    errno = ENETDOWN;
    return -1;
  });
  CHECK_FALSE(t->write(f));  // other errors are not retried
  CHECK(t->error().find("write") != std::string::npos);
}

TEST_CASE("SocketCAN: a CAN link over it stamps events with the kernel's receive time") {
  Pair p;
  std::string error;
  auto t = host::SocketCanTransport::adopt(p.ours, error);
  REQUIRE(t != nullptr);
  host::SocketCanTransport& raw = *t;
  host::CanBandLink link(std::move(t), 1);
  const proto::CanFrame hb = proto::can::encode_heartbeat(
      proto::can::Heartbeat{proto::can::NodeState::running, proto::kProtocolVersion, 0, 1234}, 1);
  p.send(host::to_socketcan(hb));
  ::usleep(10000);
  const host::LinkEvent e = link.poll(100);
  REQUIRE(e.kind == host::LinkEvent::Kind::heartbeat);
  CHECK(e.heartbeat.uptime_ms == 1234);
  CHECK(e.rx_host_us == raw.last_rx_host_us());
  CHECK(e.rx_host_us < host::steady_now_us() - 8000);
}

TEST_CASE("the kernel filter passes the band's own frames at its id base and nothing else") {
  // The kernel's CAN_RAW rule (linux/can.h): a frame passes when
  // (can_id & mask) == (filter.can_id & mask), can_id carrying EFF/RTR flags.
  const auto passes = [](const can_filter& f, canid_t id) { return (id & f.can_mask) == (f.can_id & f.can_mask); };
  constexpr std::uint32_t kBase = 0x1A000000;
  const can_filter plain = host::band_filter(3, 0), moved = host::band_filter(3, kBase);
  for (const auto fn :
       {proto::can::Function::status, proto::can::Function::response, proto::can::Function::heartbeat}) {
    const canid_t std_id = proto::can::make_id(fn, 3);
    const canid_t ext_id = proto::can::make_id(fn, 3, kBase) | CAN_EFF_FLAG;
    CHECK(passes(plain, std_id));
    CHECK_FALSE(passes(plain, ext_id));
    CHECK(passes(moved, ext_id));
    CHECK_FALSE(passes(moved, std_id));
    CHECK_FALSE(passes(moved, (proto::can::make_id(fn, 4, kBase)) | CAN_EFF_FLAG));          // another node
    CHECK_FALSE(passes(moved, (proto::can::make_id(fn, 3, kBase + 0x800)) | CAN_EFF_FLAG));  // another base
    CHECK_FALSE(passes(moved, ext_id | CAN_RTR_FLAG));
    CHECK_FALSE(passes(plain, proto::can::make_id(fn, 4)));
  }
}
