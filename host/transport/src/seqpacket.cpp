#include "seqpacket.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace tonus::host::detail {

int connect_seqpacket(const std::string& path, std::string& error) {
  sockaddr_un addr{};
  if (path.size() >= sizeof addr.sun_path) {
    error = "socket path too long: " + path;
    return -1;
  }
  const int fd = ::socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    error = std::string("socket: ") + std::strerror(errno);
    return -1;
  }
  addr.sun_family = AF_UNIX;
  std::memcpy(addr.sun_path, path.c_str(), path.size());
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    error = "connect " + path + ": " + std::strerror(errno);
    ::close(fd);
    return -1;
  }
  return fd;
}

long receive_datagram(int fd, std::span<std::uint8_t> out, int timeout_ms, std::string& error) {
  pollfd p{fd, POLLIN, 0};
  for (;;) {
    const int r = ::poll(&p, 1, timeout_ms);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) {
      error = std::string("poll: ") + std::strerror(errno);
      return -1;
    }
    if (r == 0) return 0;
    break;
  }
  const ssize_t n = ::recv(fd, out.data(), out.size(), MSG_TRUNC | MSG_DONTWAIT);
  if (n == 0) {
    error = "the band closed the link";
    return -1;
  }
  if (n < 0) {
    if (errno == EAGAIN || errno == EINTR) return 0;
    error = std::string("recv: ") + std::strerror(errno);
    return -1;
  }
  return static_cast<long>(n);
}

bool send_datagram(int fd, std::span<const std::uint8_t> bytes, std::string& error) {
  const ssize_t n = ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL);
  if (n == static_cast<ssize_t>(bytes.size())) return true;
  error = n < 0 ? std::string("send: ") + std::strerror(errno) : "short send";
  return false;
}

}  // namespace tonus::host::detail
