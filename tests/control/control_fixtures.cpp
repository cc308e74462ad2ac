#include "control_fixtures.hpp"

#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <doctest/doctest.h>

#include <algorithm>
#include <thread>

namespace tonus::control::testing {

void FakeHandler::enter(const char* name) {
  const int now = ++concurrent_;
  int seen = max_concurrent.load();
  while (now > seen && !max_concurrent.compare_exchange_weak(seen, now)) {
  }
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    calls_.emplace_back(name);
  }
  if (delay.count() > 0) std::this_thread::sleep_for(delay);
}

void FakeHandler::leave() { --concurrent_; }

std::vector<std::string> FakeHandler::calls() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return calls_;
}

Reply FakeHandler::spawn_gift(const GiftRequest& request) {
  enter("spawn_gift");
  last_gift = request;
  leave();
  return Reply::ok({{"id", 7}, {"kind", std::string(to_string(request.kind))}}, 201);
}

Reply FakeHandler::clear_gifts() {
  enter("clear_gifts");
  leave();
  return Reply::ok({{"removed", 2}});
}

Reply FakeHandler::set_stiffness_override(const std::optional<Levels>& levels) {
  enter("set_stiffness_override");
  last_levels = levels;
  leave();
  return Reply::ok({{"override", levels ? nlohmann::json(*levels) : nlohmann::json(nullptr)}});
}

Reply FakeHandler::calibrate(CalibrationCommand command) {
  enter("calibrate");
  last_calibration = command;
  leave();
  if (command == CalibrationCommand::abort) return Reply::error(409, "no calibration running");
  return Reply::ok({{"phase", std::string(to_string(command))}}, 202);
}

Reply FakeHandler::status() {
  enter("status");
  leave();
  if (throw_in_status) throw std::runtime_error("band unplugged");
  return Reply::ok({{"state", "running"}, {"levels", {0.1, 0.2, 0.3, 0.4}}}, status_code);
}

RunningServer::RunningServer(ServerLimits limits) : server(std::make_unique<ControlServer>(handler, limits)) {
  const std::string error = server->start("127.0.0.1", 0);
  REQUIRE_MESSAGE(error.empty(), error);
  REQUIRE(server->port() > 0);
}

int connect_loopback(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

std::string raw_exchange(int port, const std::string& bytes, bool half_close, std::chrono::milliseconds timeout) {
  const int fd = connect_loopback(port);
  if (fd < 0) return {};
  std::size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<std::size_t>(n);
  }
  if (half_close) ::shutdown(fd, SHUT_WR);
  std::string reply;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) break;
    char buf[4096];
    const ssize_t n = ::recv(fd, buf, sizeof(buf), 0);
    if (n <= 0) break;
    reply.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return reply;
}

int raw_status(const std::string& reply) {
  if (reply.rfind("HTTP/1.", 0) != 0 || reply.size() < 12) return 0;
  return std::atoi(reply.substr(9, 3).c_str());
}

int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = 0;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof(addr);
  int port = 0;
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) == 0) {
    port = ntohs(addr.sin_port);
  }
  ::close(fd);
  return port;
}

}  // namespace tonus::control::testing
