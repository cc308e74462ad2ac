#include "tonus/host/transport/can_transport.hpp"

#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

#include "seqpacket.hpp"
#include "tonus/host/transport/host_clock.hpp"

namespace tonus::host {

can_frame to_socketcan(const proto::CanFrame& f) {
  can_frame out{};
  const bool ext = (f.flags & proto::CanFrame::kExtended) != 0;
  out.can_id = f.id & (ext ? CAN_EFF_MASK : CAN_SFF_MASK);
  if (ext) out.can_id |= CAN_EFF_FLAG;
  if ((f.flags & proto::CanFrame::kRemote) != 0) out.can_id |= CAN_RTR_FLAG;
  if ((f.flags & proto::CanFrame::kErrorFrame) != 0) out.can_id |= CAN_ERR_FLAG;
  out.len = f.dlc > 8 ? 8 : f.dlc;
  std::memcpy(out.data, f.data.data(), out.len);
  return out;
}

proto::CanFrame from_socketcan(const can_frame& f) {
  proto::CanFrame out{};
  const bool ext = (f.can_id & CAN_EFF_FLAG) != 0;
  out.id = f.can_id & (ext ? CAN_EFF_MASK : CAN_SFF_MASK);
  if (ext) out.flags |= proto::CanFrame::kExtended;
  if ((f.can_id & CAN_RTR_FLAG) != 0) out.flags |= proto::CanFrame::kRemote;
  if ((f.can_id & CAN_ERR_FLAG) != 0) out.flags |= proto::CanFrame::kErrorFrame;
  out.dlc = f.len > 8 ? 8 : f.len;
  std::memcpy(out.data.data(), f.data, out.dlc);
  return out;
}

namespace {

bool set_option(int fd, int level, int name, const void* value, socklen_t size, const char* what, std::string& error) {
  if (::setsockopt(fd, level, name, value, size) == 0) return true;
  error = std::string("setsockopt ") + what + ": " + std::strerror(errno);
  return false;
}

bool enable_timestamps(int fd, std::string& error) {
  const int on = 1;
  return set_option(fd, SOL_SOCKET, SO_TIMESTAMP, &on, sizeof on, "SO_TIMESTAMP", error);
}

// A CLOCK_REALTIME kernel stamp as host steady time: both clocks read now, the
// stamp's age carried over (steady is what the rest of the host uses).
std::int64_t realtime_to_steady_us(const timeval& tv) {
  const auto wall_now =
      std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
          .count();
  const std::int64_t stamp = static_cast<std::int64_t>(tv.tv_sec) * 1000000 + tv.tv_usec;
  const std::int64_t age = wall_now - stamp;
  return steady_now_us() - (age > 0 ? age : 0);
}

}  // namespace

can_filter band_filter(std::uint8_t node, std::uint32_t id_base) {
  // Every function of the ID plan shares the node bits; data frames only. At
  // base 0 the frames are standard; otherwise extended, with the base's bits.
  const auto node_bits = static_cast<canid_t>(node & proto::can::kNodeMask);
  if (id_base == 0) return {node_bits, static_cast<canid_t>(proto::can::kNodeMask | CAN_EFF_FLAG | CAN_RTR_FLAG)};
  return {static_cast<canid_t>(id_base | node_bits | CAN_EFF_FLAG),
          static_cast<canid_t>((CAN_EFF_MASK & ~canid_t{0x7FF}) | proto::can::kNodeMask | CAN_EFF_FLAG | CAN_RTR_FLAG)};
}

bool configure_can_socket(int fd, std::uint8_t node, std::string& error, std::uint32_t id_base) {
  const can_filter filter = band_filter(node, id_base);
  if (!set_option(fd, SOL_CAN_RAW, CAN_RAW_FILTER, &filter, sizeof filter, "CAN_RAW_FILTER", error)) return false;
  // Every error class, so that bus-off and controller problems are seen.
  const can_err_mask_t errors = CAN_ERR_MASK;
  if (!set_option(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &errors, sizeof errors, "CAN_RAW_ERR_FILTER", error)) {
    return false;
  }
  return enable_timestamps(fd, error);
}

SocketCanTransport::SocketCanTransport(int fd)
    : fd_(fd),
      writer_([](int f, const void* data, std::size_t size) { return static_cast<long>(::write(f, data, size)); }) {}

std::unique_ptr<SocketCanTransport> SocketCanTransport::open(const std::string& iface, std::uint8_t node,
                                                             std::string& error, std::uint32_t id_base) {
  if (iface.empty() || iface.size() >= IFNAMSIZ) {
    error = "bad CAN interface name '" + iface + "'";
    return nullptr;
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    error = "cannot open CAN interface '" + iface + "': socket(PF_CAN): " + std::strerror(errno) +
            " (is the can module loaded?)";
    return nullptr;
  }
  ifreq ifr{};
  std::memcpy(ifr.ifr_name, iface.c_str(), iface.size());
  if (::ioctl(fd, SIOCGIFINDEX, &ifr) != 0) {
    error = "no CAN interface '" + iface + "': " + std::strerror(errno);
    ::close(fd);
    return nullptr;
  }
  if (!configure_can_socket(fd, node, error, id_base)) {
    error = iface + ": " + error;
    ::close(fd);
    return nullptr;
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    error = "bind " + iface + ": " + std::strerror(errno);
    ::close(fd);
    return nullptr;
  }
  return std::unique_ptr<SocketCanTransport>(new SocketCanTransport(fd));
}

std::unique_ptr<SocketCanTransport> SocketCanTransport::adopt(int fd, std::string& error) {
  if (!enable_timestamps(fd, error)) {
    ::close(fd);
    return nullptr;
  }
  return std::unique_ptr<SocketCanTransport>(new SocketCanTransport(fd));
}

SocketCanTransport::~SocketCanTransport() {
  if (fd_ >= 0) ::close(fd_);
}

void SocketCanTransport::on_error_frame(const can_frame& f) {
  ++status_.error_frames;
  if ((f.can_id & CAN_ERR_BUSOFF) != 0) {
    if (!status_.bus_off) ++status_.bus_off_events;
    status_.bus_off = true;
  }
  if ((f.can_id & CAN_ERR_RESTARTED) != 0) {
    ++status_.restarts;
    status_.bus_off = false;
  }
  if ((f.can_id & CAN_ERR_CRTL) != 0) ++status_.controller_problems;
}

int SocketCanTransport::read(proto::CanFrame& out, int timeout_ms) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd p{fd_, POLLIN, 0};
    const int r = ::poll(&p, 1, left.count() > 0 ? static_cast<int>(left.count()) : 0);
    if (r == 0 || (r < 0 && errno == EINTR)) return 0;
    if (r < 0) {
      error_ = std::string("poll: ") + std::strerror(errno);
      return -1;
    }
    can_frame f{};
    iovec iov{&f, sizeof f};
    alignas(cmsghdr) std::array<char, CMSG_SPACE(sizeof(timeval))> control{};
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control.data();
    msg.msg_controllen = control.size();
    const ssize_t n = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    if (n <= 0) {
      error_ = n < 0 ? std::string("recvmsg: ") + std::strerror(errno) : "the CAN socket was closed";
      return -1;
    }
    if (n != static_cast<ssize_t>(sizeof f)) continue;  // not a classic frame (CAN FD): not ours
    last_rx_host_us_ = 0;
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMP) {
        timeval tv{};
        std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
        last_rx_host_us_ = realtime_to_steady_us(tv);
      }
    }
    if ((f.can_id & CAN_ERR_FLAG) != 0) {
      on_error_frame(f);
      continue;
    }
    out = from_socketcan(f);
    return 1;
  }
}

bool SocketCanTransport::write(const proto::CanFrame& frame) {
  const can_frame f = to_socketcan(frame);
  // ENOBUFS: the interface's queue is full. poll() does not wait for room on a
  // CAN_RAW socket, so retry on a short timer, then give up (counted).
  constexpr int kAttempts = 20;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    const long n = writer_(fd_, &f, sizeof f);
    if (n == static_cast<long>(sizeof f)) return true;
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == ENOBUFS) {
      ++status_.tx_retries;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
      continue;
    }
    error_ = n < 0 ? std::string("write: ") + std::strerror(errno) : "short CAN write";
    return false;
  }
  ++status_.tx_dropped;
  error_ = "write: the CAN transmit queue stayed full (ENOBUFS)";
  return false;
}

std::unique_ptr<SeqpacketCanTransport> SeqpacketCanTransport::connect(const std::string& path, std::string& error) {
  const int fd = detail::connect_seqpacket(path, error);
  if (fd < 0) return nullptr;
  return std::make_unique<SeqpacketCanTransport>(fd);
}

SeqpacketCanTransport::~SeqpacketCanTransport() {
  if (fd_ >= 0) ::close(fd_);
}

int SeqpacketCanTransport::read(proto::CanFrame& out, int timeout_ms) {
  for (;;) {
    can_frame f{};
    const long n =
        detail::receive_datagram(fd_, std::span(reinterpret_cast<std::uint8_t*>(&f), sizeof f), timeout_ms, error_);
    if (n <= 0) return static_cast<int>(n);
    if (n != static_cast<long>(sizeof f)) continue;  // CAN_RAW would not deliver it either
    out = from_socketcan(f);
    return 1;
  }
}

bool SeqpacketCanTransport::write(const proto::CanFrame& frame) {
  const can_frame f = to_socketcan(frame);
  return detail::send_datagram(fd_, std::span(reinterpret_cast<const std::uint8_t*>(&f), sizeof f), error_);
}

}  // namespace tonus::host
