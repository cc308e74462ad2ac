// Raw loopback sockets and the small scene and frame of the viewer's tests.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>

#include "viewer_fixtures.hpp"

namespace tonus::viewer::testing {

std::vector<nlohmann::json> of_type(const std::vector<nlohmann::json>& messages, const std::string& type) {
  std::vector<nlohmann::json> out;
  for (const auto& m : messages) {
    if (m.is_object() && m.value("type", "") == type) out.push_back(m);
  }
  return out;
}

int connect_loopback(int port, int rcvbuf) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  if (rcvbuf > 0) ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof(rcvbuf));
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

namespace {

bool send_all(int fd, const std::string& bytes) {
  std::size_t sent = 0;
  while (sent < bytes.size()) {
    const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return false;
    sent += static_cast<std::size_t>(n);
  }
  return true;
}

// Reads until the peer closes, `stop(buffer)` holds, or `timeout` passes.
std::string read_until(int fd, std::chrono::milliseconds timeout, const std::function<bool(const std::string&)>& stop) {
  std::string buffer;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  char chunk[8192];
  while (!stop(buffer)) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) break;
    const ssize_t n = ::recv(fd, chunk, sizeof(chunk), 0);
    if (n <= 0) break;
    buffer.append(chunk, static_cast<std::size_t>(n));
  }
  return buffer;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace

std::string HttpReply::header(const std::string& name) const {
  const std::string key = "\r\n" + name + ":";
  const auto at = headers.find(key);
  if (at == std::string::npos) return "";
  const auto start = headers.find_first_not_of(' ', at + key.size());
  const auto end = headers.find("\r\n", start);
  return headers.substr(start, end - start);
}

HttpReply http_raw(int port, const std::string& request, std::chrono::milliseconds timeout) {
  HttpReply reply;
  const int fd = connect_loopback(port);
  if (fd < 0) return reply;
  if (send_all(fd, request)) {
    const std::string raw = read_until(fd, timeout, [](const std::string&) { return false; });
    const auto end = raw.find("\r\n\r\n");
    if (raw.rfind("HTTP/1.", 0) == 0 && raw.size() > 12) reply.status = std::atoi(raw.substr(9, 3).c_str());
    if (end != std::string::npos) {
      reply.headers = lower(raw.substr(0, end + 2));
      reply.body = raw.substr(end + 4);
    }
  }
  ::close(fd);
  return reply;
}

HttpReply http_get(int port, const std::string& target, const std::string& method, const Headers& headers) {
  std::string request = method + " " + target + " HTTP/1.1\r\n";
  bool has_host = false;
  for (const auto& [name, value] : headers) {
    request.append(name).append(": ").append(value).append("\r\n");
    has_host = has_host || lower(name) == "host";
  }
  if (!has_host) request += "Host: 127.0.0.1:" + std::to_string(port) + "\r\n";
  request += "Connection: close\r\n\r\n";
  return http_raw(port, request);
}

int lazy_websocket(int port, int rcvbuf) {
  const int fd = connect_loopback(port, rcvbuf);
  if (fd < 0) return -1;
  const std::string request = "GET /ws HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) +
                              "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                              "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
  if (!send_all(fd, request)) {
    ::close(fd);
    return -1;
  }
  // Read the 101 response byte by byte, so nothing after it is consumed.
  std::string head;
  char c = 0;
  while (head.find("\r\n\r\n") == std::string::npos && head.size() < 4096) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 3000) <= 0 || ::recv(fd, &c, 1, 0) != 1) break;
    head += c;
  }
  if (head.rfind("HTTP/1.1 101", 0) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

bool send_ws_frame(int fd, unsigned opcode, const std::string& payload) {
  std::string frame;
  frame += static_cast<char>(0x80U | (opcode & 0x0fU));
  const std::size_t n = payload.size();
  if (n < 126) {
    frame += static_cast<char>(0x80U | n);
  } else {
    frame += static_cast<char>(0x80U | 126U);
    frame += static_cast<char>((n >> 8U) & 0xffU);
    frame += static_cast<char>(n & 0xffU);
  }
  const std::string mask = "\x12\x34\x56\x78";
  frame += mask;
  for (std::size_t i = 0; i < n; ++i) frame += static_cast<char>(payload[i] ^ mask[i % 4]);
  return send_all(fd, frame);
}

std::vector<std::pair<unsigned, std::string>> parse_ws_frames(const std::string& bytes) {
  std::vector<std::pair<unsigned, std::string>> frames;
  std::size_t at = 0;
  auto byte = [&](std::size_t i) { return static_cast<std::size_t>(static_cast<unsigned char>(bytes[i])); };
  while (at + 2 <= bytes.size()) {
    const unsigned opcode = static_cast<unsigned>(byte(at)) & 0x0fU;
    std::size_t n = byte(at + 1) & 0x7fU;
    std::size_t header = 2;
    if (n == 126) {
      if (at + 4 > bytes.size()) break;
      n = (byte(at + 2) << 8U) | byte(at + 3);
      header = 4;
    } else if (n == 127) {
      if (at + 10 > bytes.size()) break;
      n = 0;
      for (std::size_t i = 0; i < 8; ++i) n = (n << 8U) | byte(at + 2 + i);
      header = 10;
    }
    if (at + header + n > bytes.size()) break;
    frames.emplace_back(opcode, bytes.substr(at + header, n));
    at += header + n;
  }
  return frames;
}

std::string read_raw(int fd, std::chrono::milliseconds timeout) {
  return read_until(fd, timeout, [](const std::string&) { return false; });
}

Scene small_scene() {
  Scene s;
  s.mode = "live";
  s.bones = {{"Hips", -1, 1, {{0.0, 0.0, 0.9}, {0.0, 0.0, 0.0, 1.0}}},
             {"Chest", 0, 1, {{0.0, 0.0, 1.2}, {0.0, 0.0, 0.0, 1.0}}},
             {"RightHand", 1, 0, {{0.0, -0.7, 1.4}, {0.0, 0.0, std::sqrt(0.5), std::sqrt(0.5)}}}};
  GeomInfo capsule;
  capsule.bone = 0;
  capsule.shape = "capsule";
  capsule.radius_m = 0.1;
  capsule.half_length_m = 0.05;
  capsule.pos = {0.0, 0.0, 0.05};
  GeomInfo sphere;
  sphere.bone = 1;
  sphere.shape = "sphere";
  sphere.radius_m = 0.12;
  GeomInfo box;
  box.bone = 2;
  box.shape = "box";
  box.half_extents_m = {0.04, 0.02, 0.08};
  box.quat = {0.0, 0.0, std::sqrt(0.5), std::sqrt(0.5)};
  s.geoms = {capsule, sphere, box};
  s.groups = {"right_arm", "trunk"};
  s.gift_bones = {"Chest", "RightHand"};
  s.ground_z_m = 0.0;
  s.rate_hz = 1000.0;
  return s;
}

Frame small_frame(std::uint64_t tick) {
  Frame f;
  f.tick = tick;
  f.time_s = static_cast<double>(tick) * 1e-3;
  const double sway = 0.05 * std::sin(f.time_s);
  f.avatar = {{{sway, 0.0, 1.0}, {0.0, 0.0, 0.0, 1.0}},
              {{sway, 0.0, 1.3}, {0.0, 0.0, 0.0, 1.0}},
              {{sway, -0.7, 1.4}, {0.0, 0.0, 0.0, 1.0}}};
  f.reference = f.avatar;
  f.stiffness = {0.5, 0.25};
  f.tracker_state = "live";
  f.band.source = "sim";
  f.band.connected = true;
  f.band.live = true;
  f.metrics.ticks = tick;
  f.zmp = Vec2{0.0, 0.0};
  f.support = {{-0.1, -0.15}, {0.15, -0.15}, {0.15, 0.15}, {-0.1, 0.15}};
  return f;
}

}  // namespace tonus::viewer::testing
