#include "vmc_fixtures.hpp"

#include <arpa/inet.h>
#include <doctest/doctest.h>
#include <lo/lo.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>

#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/joint_limits.hpp"

namespace tonus::vmc::test {

const sim::Model& humanoid() {
  static const sim::BuildResult built = sim::build_humanoid(sim::HumanoidSpec{});
  REQUIRE_MESSAGE(built, built.error);
  return *built.model;
}

std::vector<double> lively_qpos(const sim::Vec3& root_pos, const sim::Quat& root_rot) {
  const sim::Model& m = humanoid();
  std::vector<double> q(m.qpos0.begin(), m.qpos0.begin() + m.nq);
  q[0] = root_pos.x();
  q[1] = root_pos.y();
  q[2] = root_pos.z();
  const sim::Quat r = root_rot.normalized();
  q[3] = r.w();
  q[4] = r.x();
  q[5] = r.y();
  q[6] = r.z();
  const auto ball = [&](sim::Bone b, const sim::Vec3& axis, double angle) {
    const sim::Body& body = m.bodies[sim::index(b)];
    REQUIRE(body.joint == sim::JointType::ball);
    sim::Quat j(Eigen::AngleAxisd(angle, axis.normalized()));
    sim::clamp_ball(body.limit, j);
    const auto a = static_cast<std::size_t>(body.qpos_adr);
    q[a] = j.w();
    q[a + 1] = j.x();
    q[a + 2] = j.y();
    q[a + 3] = j.z();
  };
  const auto hinge = [&](sim::Bone b, double share) {
    const sim::Body& body = m.bodies[sim::index(b)];
    REQUIRE(body.joint == sim::JointType::hinge);
    double angle = body.limit.lower_rad + share * (body.limit.upper_rad - body.limit.lower_rad);
    sim::clamp_hinge(body.limit, angle);
    q[static_cast<std::size_t>(body.qpos_adr)] = angle;
  };
  ball(sim::Bone::LeftUpperArm, {1.0, 0.2, 0.1}, 1.0);    // raised sideways, a little forward
  ball(sim::Bone::RightUpperArm, {-1.0, 0.0, 0.3}, 0.7);  // raised, turned in
  hinge(sim::Bone::LeftLowerArm, 0.4);
  hinge(sim::Bone::RightLowerArm, 0.7);
  hinge(sim::Bone::LeftLowerLeg, 0.3);
  ball(sim::Bone::LeftUpperLeg, {0.1, -1.0, 0.0}, 0.4);  // hip flexed
  ball(sim::Bone::Head, {0.0, 0.2, 1.0}, 0.4);           // looking left, tilted
  ball(sim::Bone::Spine, {0.0, 1.0, 0.0}, 0.15);         // leaning forward
  ball(sim::Bone::LeftHand, {1.0, 0.0, 0.5}, 0.3);
  return q;
}

UdpSocket::UdpSocket() {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  REQUIRE(fd_ >= 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  REQUIRE(::bind(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof(a)) == 0);
  socklen_t len = sizeof(a);
  REQUIRE(::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len) == 0);
  port_ = ntohs(a.sin_port);
}

UdpSocket::~UdpSocket() { ::close(fd_); }

void UdpSocket::send_to(int port, const std::vector<unsigned char>& datagram) const {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  const ssize_t n =
      ::sendto(fd_, datagram.data(), datagram.size(), 0, reinterpret_cast<const sockaddr*>(&a), sizeof(a));
  REQUIRE(n == static_cast<ssize_t>(datagram.size()));
}

std::vector<std::vector<unsigned char>> UdpSocket::receive_all(int quiet_ms) const {
  std::vector<std::vector<unsigned char>> out;
  std::vector<unsigned char> buf(65536);
  for (;;) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, out.empty() ? 2000 : quiet_ms) <= 0) break;
    const ssize_t n = ::recv(fd_, buf.data(), buf.size(), 0);
    if (n < 0) break;
    out.emplace_back(buf.begin(), buf.begin() + n);
  }
  return out;
}

namespace {

void decode_one(std::vector<unsigned char> bytes, std::size_t datagram, bool in_bundle, std::vector<OscMessage>& out) {
  int result = 0;
  lo_message m = lo_message_deserialise(bytes.data(), bytes.size(), &result);
  REQUIRE_MESSAGE(m != nullptr, "liblo refused a message: " << result);
  OscMessage o;
  o.path = reinterpret_cast<const char*>(bytes.data());
  o.types = lo_message_get_types(m);
  o.datagram = datagram;
  o.in_bundle = in_bundle;
  lo_arg** argv = lo_message_get_argv(m);
  // argv points into 4-byte aligned data; lo_arg asks for 8: copy the bytes out.
  const auto as = [&](std::size_t k, auto v) {
    std::memcpy(&v, static_cast<const void*>(argv[k]), sizeof(v));
    return v;
  };
  for (std::size_t k = 0; k < o.types.size(); ++k) {
    switch (o.types[k]) {
      case 'f': o.numbers.push_back(static_cast<double>(as(k, 0.0F))); break;
      case 'd': o.numbers.push_back(as(k, 0.0)); break;
      case 'i': o.numbers.push_back(as(k, std::int32_t{0})); break;
      case 's': o.strings.emplace_back(reinterpret_cast<const char*>(argv[k])); break;
      default: FAIL("unexpected type " << o.types[k]);
    }
  }
  lo_message_free(m);
  out.push_back(o);
}

std::uint32_t be32(const unsigned char* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | std::uint32_t{p[3]};
}

}  // namespace

std::vector<OscMessage> decode_all(const std::vector<std::vector<unsigned char>>& datagrams) {
  std::vector<OscMessage> out;
  for (std::size_t d = 0; d < datagrams.size(); ++d) {
    const std::vector<unsigned char>& g = datagrams[d];
    REQUIRE(g.size() % 4 == 0);
    if (g.size() >= 8 && std::memcmp(g.data(), "#bundle", 8) == 0) {
      REQUIRE(g.size() >= 16);
      std::size_t pos = 16;
      while (pos < g.size()) {
        REQUIRE(g.size() - pos >= 4);
        const std::uint32_t len = be32(g.data() + pos);
        pos += 4;
        REQUIRE(len <= g.size() - pos);
        decode_one(std::vector<unsigned char>(g.begin() + static_cast<std::ptrdiff_t>(pos),
                                              g.begin() + static_cast<std::ptrdiff_t>(pos + len)),
                   d, true, out);
        pos += len;
      }
    } else {
      decode_one(g, d, false, out);
    }
  }
  return out;
}

std::vector<unsigned char> osc_message(const std::string& path, const std::string& types,
                                       const std::vector<double>& numbers, const std::vector<std::string>& strings) {
  lo_message m = lo_message_new();
  std::size_t n = 0;
  std::size_t s = 0;
  for (const char t : types) {
    switch (t) {
      case 'f': lo_message_add_float(m, static_cast<float>(numbers.at(n++))); break;
      case 'd': lo_message_add_double(m, numbers.at(n++)); break;
      case 'i': lo_message_add_int32(m, static_cast<std::int32_t>(numbers.at(n++))); break;
      case 's': lo_message_add_string(m, strings.at(s++).c_str()); break;
      default: FAIL("unsupported type " << t);
    }
  }
  std::size_t size = 0;
  void* data = lo_message_serialise(m, path.c_str(), nullptr, &size);
  const auto* bytes = static_cast<const unsigned char*>(data);
  std::vector<unsigned char> out(bytes, bytes + size);
  std::free(data);
  lo_message_free(m);
  return out;
}

std::vector<unsigned char> osc_bundle(const std::vector<std::vector<unsigned char>>& elements) {
  std::vector<unsigned char> out{'#', 'b', 'u', 'n', 'd', 'l', 'e', 0, 0, 0, 0, 0, 0, 0, 0, 1};  // immediate
  for (const std::vector<unsigned char>& e : elements) {
    const auto len = static_cast<std::uint32_t>(e.size());
    for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<unsigned char>(len >> shift));
    out.insert(out.end(), e.begin(), e.end());
  }
  return out;
}

bool pump(VmcReceiver& receiver, const std::function<bool()>& done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    receiver.receive(10);
  }
  return true;
}

}  // namespace tonus::vmc::test
