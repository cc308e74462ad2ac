// A third-party reader: liblo's oscdump (Debian liblo-tools) listens on a
// free port; one frame is sent to it and its text output checked: addresses,
// type tags, bone names, values (printed with 6 decimals).
#include <doctest/doctest.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tonus/host/vmc/sender.hpp"
#include "tonus/sim/human_bones.hpp"
#include "vmc_fixtures.hpp"

extern char** environ;

using namespace tonus;
using sim::Quat;
using sim::Vec3;

namespace {

struct Line {
  std::string path;
  std::string types;
  std::vector<std::string> args;
};

// "<time tag> <path> <types> <args...>", strings in double quotes (no spaces in ours).
Line parse(const std::string& text) {
  std::istringstream in(text);
  Line l;
  std::string tag;
  in >> tag >> l.path >> l.types;
  for (std::string a; in >> a;) {
    if (a.size() >= 2 && a.front() == '"' && a.back() == '"') a = a.substr(1, a.size() - 2);
    l.args.push_back(a);
  }
  return l;
}

class Oscdump {
 public:
  explicit Oscdump(int port) {
    int fds[2];
    REQUIRE(::pipe2(fds, O_CLOEXEC) == 0);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, fds[1], STDOUT_FILENO);
    const std::string p = std::to_string(port);
    std::string prog = TONUS_OSCDUMP;
    std::string line_buffered = "-L";
    std::string port_arg = p;
    char* argv[] = {prog.data(), line_buffered.data(), port_arg.data(), nullptr};
    const int rc = posix_spawn(&pid_, TONUS_OSCDUMP, &fa, nullptr, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    ::close(fds[1]);
    out_ = fds[0];
    REQUIRE(rc == 0);
  }
  ~Oscdump() {
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    ::close(out_);
  }
  Oscdump(const Oscdump&) = delete;
  Oscdump& operator=(const Oscdump&) = delete;

  // Whatever it printed within `ms`, appended to the lines so far.
  void read(int ms) {
    pollfd p{out_, POLLIN, 0};
    if (::poll(&p, 1, ms) <= 0) return;
    char buf[4096];
    const ssize_t n = ::read(out_, buf, sizeof(buf));
    if (n <= 0) return;
    pending_.append(buf, static_cast<std::size_t>(n));
    for (std::size_t nl; (nl = pending_.find('\n')) != std::string::npos;) {
      lines.push_back(pending_.substr(0, nl));
      pending_.erase(0, nl + 1);
    }
  }
  std::vector<std::string> lines;

 private:
  pid_t pid_ = 0;
  int out_ = -1;
  std::string pending_;
};

}  // namespace

TEST_CASE("vmc oscdump reads what the sender sends") {
  if (::access(TONUS_OSCDUMP, X_OK) != 0) {
    MESSAGE("skipped: " TONUS_OSCDUMP " is absent (Debian package liblo-tools)");
    return;
  }
  int port = 0;
  {
    const vmc::test::UdpSocket probe;  // a free port, released for oscdump
    port = probe.port();
  }
  Oscdump dump(port);
  vmc::SenderOptions o;
  o.port = port;
  vmc::VmcSender sender(o);
  REQUIRE(sender.ok());
  vmc::VmcPose pose;
  REQUIRE(vmc::pose_from_qpos(vmc::test::humanoid(),
                              vmc::test::lively_qpos(Vec3(0.2, 0.1, 0.95), Quat(Eigen::AngleAxisd(0.5, Vec3::UnitZ()))),
                              pose));
  const std::array<vmc::VmcObject, 1> objects{
      vmc::object_to_vmc(7, vmc::ObjectKind::ball, 0.22, Vec3(1.0, 0.5, 1.4), Quat::Identity())};
  const std::array<float, 4> stiffness{0.125F, 0.25F, 0.5F, 1.0F};

  // oscdump needs a moment to bind: send a frame every 100 ms until one is dumped whole.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  std::vector<Line> frame;
  while (frame.empty() && std::chrono::steady_clock::now() < deadline) {
    REQUIRE(sender.send(pose, 4.25, objects, &stiffness));
    for (int k = 0; k < 10; ++k) dump.read(10);
    // The last complete frame: from an OK to the next Stiffness.
    std::vector<Line> current;
    for (const std::string& text : dump.lines) {
      const Line l = parse(text);
      if (l.path == "/VMC/Ext/OK") current.clear();
      current.push_back(l);
      if (l.path == "/tonus/Stiffness" && current.front().path == "/VMC/Ext/OK") frame = current;
    }
  }
  REQUIRE_MESSAGE(!frame.empty(), "oscdump printed no whole frame within 5 s (" << dump.lines.size() << " lines)");

  std::map<std::string, int> seen;
  for (const Line& l : frame) ++seen[l.path];
  CHECK(seen["/VMC/Ext/OK"] == 1);
  CHECK(seen["/VMC/Ext/T"] == 1);
  CHECK(seen["/VMC/Ext/Root/Pos"] == 1);
  CHECK(seen["/VMC/Ext/Bone/Pos"] == static_cast<int>(sim::kBoneCount));
  CHECK(seen["/tonus/Object/Pos"] == 1);
  CHECK(seen["/tonus/Stiffness"] == 1);
  CHECK(seen.size() == 6);

  const auto num = [](const std::string& s) { return std::stod(s); };
  for (const Line& l : frame) {
    CAPTURE(l.path);
    if (l.path == "/VMC/Ext/OK") {
      CHECK(l.types == "iiii");
      CHECK(l.args == std::vector<std::string>{"1", "3", "0", "1"});
    } else if (l.path == "/VMC/Ext/T") {
      CHECK(l.types == "f");
      CHECK(num(l.args.at(0)) == doctest::Approx(4.25));
    } else if (l.path == "/VMC/Ext/Root/Pos") {
      CHECK(l.types == "sfffffff");
      CHECK(l.args.at(0) == "root");
      for (std::size_t k = 1; k < 7; ++k) CHECK(num(l.args.at(k)) == doctest::Approx(0.0));
      CHECK(num(l.args.at(7)) == doctest::Approx(1.0));
    } else if (l.path == "/VMC/Ext/Bone/Pos") {
      CHECK(l.types == "sfffffff");
      const std::optional<sim::Bone> b = sim::bone_from_name(l.args.at(0));
      REQUIRE_MESSAGE(b, l.args.at(0));
      const vmc::UnityTransform& t = pose.bone[sim::index(*b)];
      const std::array<double, 7> want{t.pos_m.x(), t.pos_m.y(), t.pos_m.z(), t.rot.x(),
                                       t.rot.y(),   t.rot.z(),   t.rot.w()};
      for (std::size_t k = 0; k < 7; ++k) CHECK(std::abs(num(l.args.at(k + 1)) - want[k]) < 1.5e-6);
    } else if (l.path == "/tonus/Object/Pos") {
      CHECK(l.types == "isffffffff");
      CHECK(l.args.at(0) == "7");
      CHECK(l.args.at(1) == "ball");
      CHECK(num(l.args.at(2)) == doctest::Approx(0.22));
      // Internal (1, 0.5, 1.4) -> Unity (-0.5, 1.4, 1).
      CHECK(num(l.args.at(3)) == doctest::Approx(-0.5));
      CHECK(num(l.args.at(4)) == doctest::Approx(1.4));
      CHECK(num(l.args.at(5)) == doctest::Approx(1.0));
    } else if (l.path == "/tonus/Stiffness") {
      CHECK(l.types == "ffff");
      CHECK(num(l.args.at(0)) == doctest::Approx(0.125));
      CHECK(num(l.args.at(3)) == doctest::Approx(1.0));
    }
  }
  // The hips 0.95 m up, in Unity's y.
  for (const Line& l : frame) {
    if (l.path == "/VMC/Ext/Bone/Pos" && l.args.at(0) == "Hips") CHECK(num(l.args.at(2)) == doctest::Approx(0.95));
  }
}
