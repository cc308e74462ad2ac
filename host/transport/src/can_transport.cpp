#include "tonus/host/transport/can_transport.hpp"

#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>

#include "seqpacket.hpp"

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

std::unique_ptr<SocketCanTransport> SocketCanTransport::open(const std::string& iface, std::uint8_t node,
                                                             std::string& error) {
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
  // Only this node's standard frames (every function of the ID plan shares the node bits).
  const can_filter filter{static_cast<canid_t>(node & proto::can::kNodeMask),
                          static_cast<canid_t>(proto::can::kNodeMask | CAN_EFF_FLAG | CAN_RTR_FLAG)};
  ::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, &filter, sizeof filter);
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

SocketCanTransport::~SocketCanTransport() {
  if (fd_ >= 0) ::close(fd_);
}

int SocketCanTransport::read(proto::CanFrame& out, int timeout_ms) {
  pollfd p{fd_, POLLIN, 0};
  const int r = ::poll(&p, 1, timeout_ms);
  if (r == 0 || (r < 0 && errno == EINTR)) return 0;
  if (r < 0) {
    error_ = std::string("poll: ") + std::strerror(errno);
    return -1;
  }
  can_frame f{};
  const ssize_t n = ::read(fd_, &f, sizeof f);
  if (n != static_cast<ssize_t>(sizeof f)) {
    error_ = n < 0 ? std::string("read: ") + std::strerror(errno) : "short CAN frame";
    return n < 0 ? -1 : 0;
  }
  out = from_socketcan(f);
  return 1;
}

bool SocketCanTransport::write(const proto::CanFrame& frame) {
  const can_frame f = to_socketcan(frame);
  if (::write(fd_, &f, sizeof f) == static_cast<ssize_t>(sizeof f)) return true;
  error_ = std::string("write: ") + std::strerror(errno);
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
