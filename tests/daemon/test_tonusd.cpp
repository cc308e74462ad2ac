// tonusd as the user runs it: a real process, with the band simulator as a
// real process, and the test as the avatar engine (a VMC receiver parsing
// with liblo) and as a VMC performer. Loopback only; every run ends itself.
#include <doctest/doctest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>

#include "daemon_fixtures.hpp"
#include "process.hpp"
#include "support/scratch_dir.hpp"
#include "tonus/host/control/client.hpp"
#include "tonus/host/daemon/pose_buffer.hpp"
#include "tonus/host/vmc/pose_out.hpp"
#include "tonus/host/vmc/sender.hpp"
#include "tonus/sim/human_bones.hpp"
#include "vmc_capture.hpp"

using namespace tonus;
using test::Process;
using test::VmcCapture;

namespace {

std::string temp_path(const std::string& name) { return test::scratch_path("tonusd-" + name); }

nlohmann::json run_tonusd(const std::vector<std::string>& args, const std::string& name, std::string* log = nullptr) {
  const std::string json = temp_path(name + ".json");
  std::vector<std::string> a = args;
  // Without SCHED_FIFO: the tests check behaviour, and real-time threads of a sanitizer build would
  // starve the simulator and the test itself on a 2-core machine running the suite in parallel.
  a.insert(a.end(), {"--json", json, "--no-control", "--no-viewer", "--no-realtime"});
  Process p(TONUSD, a, temp_path(name + ".log"));
  REQUIRE(p.started());
  const int rc = p.wait(std::chrono::seconds(60));
  if (log != nullptr) *log = p.output();
  INFO(p.output());
  REQUIRE(rc == 0);
  std::ifstream in(json);
  REQUIRE(in);
  return nlohmann::json::parse(in);
}

std::string write_file(const std::string& name, const std::string& text) {
  std::string path = temp_path(name);
  std::ofstream(path) << text;
  return path;
}

// The port a process logs (its first capture group), waited for up to 3 s; 0 if it never appears.
int port_in_log(const Process& p, const char* pattern) {
  const std::regex re(pattern);
  for (int i = 0; i < 300; ++i) {
    std::smatch m;
    const std::string log = p.output();
    if (std::regex_search(log, m, re)) return std::stoi(m[1]);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return 0;
}

double quat_norm(const test::OscMessage& m) {
  return std::sqrt(m.numbers[3] * m.numbers[3] + m.numbers[4] * m.numbers[4] + m.numbers[5] * m.numbers[5] +
                   m.numbers[6] * m.numbers[6]);
}

// The angle between two unit quaternions given as x y z w (either sign).
double angle_between(const std::array<double, 4>& a, const std::array<double, 4>& b) {
  const double dot = std::abs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]);
  return 2.0 * std::acos(std::min(1.0, dot));
}

// The humanoid's rest with the left arm raised 0.8 rad about the forward axis.
std::array<double, sim::kMaxQpos> left_arm_raised(const sim::Model& model) {
  std::array<double, sim::kMaxQpos> q = model.qpos0;
  const auto arm = static_cast<std::size_t>(model.bodies[sim::index(sim::Bone::LeftUpperArm)].qpos_adr);
  const sim::Quat up(Eigen::AngleAxisd(0.8, sim::Vec3::UnitX()));
  q[arm] = up.w();
  q[arm + 1] = up.x();
  q[arm + 2] = up.y();
  q[arm + 3] = up.z();
  return q;
}

}  // namespace

TEST_CASE("tonusd --demo: exits 0 with the summary's fields, the VMC output parses, every bone, unit quaternions") {
  VmcCapture capture;
  const nlohmann::json j =
      run_tonusd({"--demo", "--seconds", "6", "--vmc-port", std::to_string(capture.port())}, "demo");
  for (const char* key : {"ticks", "tick_p50_us", "tick_p99_us", "tick_max_us", "overruns", "vmc_bundles_sent",
                          "band_reports_received", "band_reports_lost", "gifts", "stiffness_min", "stiffness_max"}) {
    CHECK_MESSAGE(j.contains(key), key);
  }
  // Every 1 ms deadline of the 6 s is a tick or a skipped one (a sanitizer build skips some).
  CHECK(j["ticks"].get<double>() + j["skipped_ticks"].get<double>() > 5000);
  CHECK(j["ticks"].get<double>() > 2000);
  CHECK(j["band_reports_received"].get<double>() > 1000);  // 500 Hz for most of 6 s
  CHECK(j["vmc_bundles_sent"].get<double>() > 300);        // 60 Hz, two bundles a frame
  REQUIRE(j["gifts"].size() == 4);
  for (const auto& g : j["gifts"]) {
    CHECK(g.contains("kind"));
    CHECK(g.contains("bone"));
    CHECK(g["stiffness"].get<double>() >= 0.0);
    CHECK(g["peak_deflection_m"].get<double>() >= 0.0);
  }
  for (const char* group : {"right_arm", "left_arm", "trunk", "legs"}) {
    CHECK(j["stiffness_min"][group].get<double>() < j["stiffness_max"][group].get<double>());  // it rose and fell
  }

  // The avatar engine's side: liblo parsed every datagram; frames start with
  // /VMC/Ext/T and carry each of the 21 bones once, with unit quaternions.
  CHECK(capture.unparsed() == 0);
  CHECK(capture.max_datagram() <= 1500);
  const std::vector<test::OscMessage> msgs = capture.messages();
  std::vector<std::set<std::string>> frames;
  int bad_norm = 0, objects = 0;
  for (const auto& m : msgs) {
    if (m.path == "/VMC/Ext/T") frames.emplace_back();
    if (m.path == "/VMC/Ext/Bone/Pos" && !frames.empty()) {
      REQUIRE(m.numbers.size() >= 7);
      frames.back().insert(m.text);
      if (std::abs(quat_norm(m) - 1.0) > 1e-4) ++bad_norm;
    }
    if (m.path == "/tonus/Object/Pos") ++objects;
  }
  REQUIRE(frames.size() > 300);
  std::set<std::string> all;
  for (const auto& b : sim::kBones) all.insert(std::string(b.name));
  int complete = 0;
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) complete += frames[f] == all ? 1 : 0;
  CHECK(complete == static_cast<int>(frames.size()) - 1);
  CHECK(bad_norm == 0);
  CHECK(objects > 0);  // the gifts are shown
}

TEST_CASE("tonusd: more co-contraction on the band means stiffer drives and a smaller sag under the same cube") {
  const std::string gifts =
      write_file("gifts.toml", "[demo]\ngifts = [ { at_s = 1.5, kind = \"cube\", bone = \"RightHand\" } ]\n");
  const auto run = [&](const std::string& effort) {
    return run_tonusd({"--demo", "--seconds", "4", "--config", gifts, "--tracker", "none", "--sim-synthetic", "step",
                       "--sim-arg=--step-from", "--sim-arg=" + effort, "--sim-arg=--step-to", "--sim-arg=" + effort},
                      "effort-" + effort);
  };
  const nlohmann::json low = run("0.1");
  const nlohmann::json high = run("0.8");
  REQUIRE(low["gifts"].size() == 1);
  REQUIRE(high["gifts"].size() == 1);
  const auto& gl = low["gifts"][0];
  const auto& gh = high["gifts"][0];
  MESSAGE("effort 0.1: stiffness " << gl["stiffness"] << ", " << gl["natural_hz"] << " Hz, sag "
                                   << gl["peak_deflection_m"].get<double>() * 1e3 << " mm; effort 0.8: stiffness "
                                   << gh["stiffness"] << ", " << gh["natural_hz"] << " Hz, sag "
                                   << gh["peak_deflection_m"].get<double>() * 1e3 << " mm");
  CHECK(gh["stiffness"].get<double>() > gl["stiffness"].get<double>() + 0.3);
  CHECK(gh["natural_hz"].get<double>() > gl["natural_hz"].get<double>());
  CHECK(gl["peak_deflection_m"].get<double>() > 0.003);
  CHECK(gh["peak_deflection_m"].get<double>() < 0.7 * gl["peak_deflection_m"].get<double>());
}

TEST_CASE("tonusd: a CAN band over the simulated link streams too") {
  const std::string cfg = write_file("can.toml", "[band]\nsim_link = \"can\"\n");
  const nlohmann::json j = run_tonusd({"--seconds", "3", "--config", cfg, "--tracker", "none"}, "can");
  CHECK(j["band_reports_received"].get<double>() > 500);
  CHECK(j["band_reports_lost"].get<double>() < 10);
  CHECK(j["band_device"].get<std::string>().find("firmware") != std::string::npos);
}

TEST_CASE("tonusd: the band killed mid-stream relaxes the stiffness to the safe default, a band back takes over") {
  VmcCapture capture;
  const std::string sock = temp_path("band.sock");
  const std::vector<std::string> sim_args{"--synthetic", "step", "--step-from",  "0.8", "--step-to", "0.8",
                                          "--seconds",   "60",   "--hid-socket", sock,  "--quiet"};
  auto sim = std::make_unique<Process>(TONUS_BAND_SIM, sim_args, temp_path("sim1.log"));
  REQUIRE(sim->started());
  for (int i = 0; i < 200 && ::access(sock.c_str(), F_OK) != 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const std::string json = temp_path("kill.json");
  Process d(
      TONUSD,
      {"--no-realtime", "--seconds", "8", "--band", "socket", "--band-socket", sock, "--tracker", "none", "--vmc-port",
       std::to_string(capture.port()), "--vmc-rate", "200", "--no-control", "--no-viewer", "--json", json},
      temp_path("kill.log"));
  REQUIRE(d.started());
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));
  const std::int64_t kill_us = test::steady_us();
  sim->kill(SIGKILL);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  ::unlink(sock.c_str());
  const std::int64_t restart_us = test::steady_us();
  sim = std::make_unique<Process>(TONUS_BAND_SIM, sim_args, temp_path("sim2.log"));
  REQUIRE(d.wait(std::chrono::seconds(30)) == 0);
  INFO(d.output());

  const double safe = 0.3;  // band.safe_stiffness's default (docs/daemon.md)
  double before = -1.0;
  std::int64_t first_default_us = -1, resumed_us = -1;
  double min_while_fresh = 1.0;
  for (const auto& m : capture.messages()) {
    if (m.path != "/tonus/Stiffness" || m.numbers.size() != 4) continue;
    const double lo = *std::min_element(m.numbers.begin(), m.numbers.end());
    const double hi = *std::max_element(m.numbers.begin(), m.numbers.end());
    if (m.arrival_us < kill_us) before = lo;
    if (m.arrival_us >= kill_us && m.arrival_us < kill_us + 90'000) min_while_fresh = std::min(min_while_fresh, lo);
    if (m.arrival_us >= kill_us && first_default_us < 0 && std::abs(lo - safe) < 0.01 && std::abs(hi - safe) < 0.01) {
      first_default_us = m.arrival_us;
    }
    if (m.arrival_us >= restart_us && resumed_us < 0 && lo > 0.6) resumed_us = m.arrival_us;
  }
  MESSAGE("stiffness before the kill " << before << "; the safe default reached " << (first_default_us - kill_us) / 1000
                                       << " ms after the kill; resumed " << (resumed_us - restart_us) / 1000
                                       << " ms after the restart");
  CHECK(before > 0.6);
  CHECK(min_while_fresh > 0.6);  // held while the last report is fresh
  REQUIRE(first_default_us > 0);
  // 100 ms of silence, then at most 100 ms to the default (one 5 ms output period and scheduling slack beside).
  CHECK(first_default_us - kill_us <= 215'000);
  CHECK(first_default_us - kill_us >= 100'000);
  REQUIRE(resumed_us > 0);
  CHECK(resumed_us - restart_us < 3'500'000);  // the reopen backoff is at most 2 s
}

TEST_CASE("tonusd: a VMC performer's stream is followed, held when it stops, eased to neutral, bad OSC is counted") {
  VmcCapture capture;
  const std::string json = temp_path("performer.json");
  Process d(TONUSD,
            {"--no-realtime", "--seconds", "5", "--band", "none", "--tracker", "vmc", "--vmc-mode", "performer",
             "--listen-port", "0", "--vmc-port", std::to_string(capture.port()), "--vmc-rate", "100", "--no-control",
             "--no-viewer", "--json", json},
            temp_path("performer.log"));
  REQUIRE(d.started());
  const int listen_port = port_in_log(d, "mode on 127\\.0\\.0\\.1:([0-9]+)");
  REQUIRE(listen_port > 0);

  // The performer raises the left arm 0.8 rad (about the forward axis) and holds it.
  const sim::Model& model = test::daemon_humanoid();
  const std::array<double, sim::kMaxQpos> raised = left_arm_raised(model);
  vmc::VmcPose pose, neutral_pose;
  REQUIRE(vmc::pose_from_qpos(model, raised, pose));
  std::array<double, sim::kMaxQpos> neutral{};
  daemon::neutral_qpos(model, raised, neutral);
  REQUIRE(vmc::pose_from_qpos(model, neutral, neutral_pose));
  vmc::SenderOptions so;
  so.port = listen_port;
  vmc::VmcSender sender(so);
  REQUIRE(sender.ok());
  for (int k = 0; k < 120; ++k) {  // 2 s at 60 Hz
    sender.send(pose, k / 60.0, {}, nullptr);
    std::this_thread::sleep_for(std::chrono::microseconds(16667));
  }
  const std::int64_t stop_us = test::steady_us();
  // Bad input: 7 datagrams that are not OSC, 3 OSC messages nobody knows.
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  to.sin_port = htons(static_cast<std::uint16_t>(listen_port));
  const auto send_raw = [&](const std::string& bytes) {
    ::sendto(fd, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
  };
  for (int i = 0; i < 7; ++i)
    send_raw(i % 2 == 0 ? std::string("garbage!") : std::string("/VMC/Ext/Bone/Pos\0\0\0,sff", 24));
  for (int i = 0; i < 3; ++i) send_raw(std::string("/tonus/nonsense\0,\0\0\0", 20));
  ::close(fd);
  REQUIRE(d.wait(std::chrono::seconds(30)) == 0);
  INFO(d.output());

  const auto rot = [](const sim::Quat& q) { return std::array<double, 4>{q.x(), q.y(), q.z(), q.w()}; };
  const std::array<double, 4> want_raised = rot(pose.bone[sim::index(sim::Bone::LeftUpperArm)].rot);
  const std::array<double, 4> want_neutral = rot(neutral_pose.bone[sim::index(sim::Bone::LeftUpperArm)].rot);
  double live_err = 0.0, held_err = 0.0, neutral_err = 0.0;
  int live_n = 0, held_n = 0, neutral_n = 0;
  for (const auto& m : capture.messages()) {
    if (m.path != "/VMC/Ext/Bone/Pos" || m.text != "LeftUpperArm") continue;
    const std::array<double, 4> q{m.numbers[3], m.numbers[4], m.numbers[5], m.numbers[6]};
    const std::int64_t dt = m.arrival_us - stop_us;
    if (dt > -400'000 && dt < -100'000) {
      live_err = std::max(live_err, angle_between(q, want_raised));
      ++live_n;
    } else if (dt > 50'000 && dt < 250'000) {
      held_err = std::max(held_err, angle_between(q, want_raised));
      ++held_n;
    } else if (dt > 1'300'000) {
      neutral_err = std::max(neutral_err, angle_between(q, want_neutral));
      ++neutral_n;
    }
  }
  MESSAGE("left upper arm: off the performer's by at most " << live_err << " rad while live, " << held_err
                                                            << " rad held; off the neutral by " << neutral_err
                                                            << " rad after easing");
  REQUIRE(live_n > 10);
  REQUIRE(held_n > 10);
  REQUIRE(neutral_n > 10);
  CHECK(live_err < 0.1);
  CHECK(held_err < 0.1);
  CHECK(neutral_err < 0.1);
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  CHECK(j["tracker_vmc_malformed"].get<int>() == 7);
  CHECK(j["tracker_vmc_ignored"].get<int>() >= 3);
}

TEST_CASE("tonusd: a VMC performer's stream through the online balance filter comes the look-ahead later") {
  VmcCapture capture;
  const std::string json = temp_path("performer-balance.json");
  Process d(TONUSD,
            {"--no-realtime",
             "--seconds",
             "5",
             "--band",
             "none",
             "--tracker",
             "vmc",
             "--vmc-mode",
             "performer",
             "--balance",
             "online",
             "--listen-port",
             "0",
             "--vmc-port",
             std::to_string(capture.port()),
             "--vmc-rate",
             "100",
             "--no-control",
             "--no-viewer",
             "--json",
             json},
            temp_path("performer-balance.log"));
  REQUIRE(d.started());
  const int listen_port = port_in_log(d, "mode on 127\\.0\\.0\\.1:([0-9]+)");
  REQUIRE(listen_port > 0);

  // The performer stands (the humanoid's rest: balanced, so nothing to
  // correct), then raises the left arm 0.8 rad and holds it.
  const sim::Model& model = test::daemon_humanoid();
  const std::array<double, sim::kMaxQpos> raised = left_arm_raised(model);
  vmc::VmcPose standing, lifted;
  REQUIRE(vmc::pose_from_qpos(model, model.qpos0, standing));
  REQUIRE(vmc::pose_from_qpos(model, raised, lifted));
  vmc::SenderOptions so;
  so.port = listen_port;
  vmc::VmcSender sender(so);
  REQUIRE(sender.ok());
  std::int64_t lift_us = 0;
  for (int k = 0; k < 180; ++k) {  // 1.5 s standing, 1.5 s raised, at 60 Hz
    if (k == 90) lift_us = test::steady_us();
    sender.send(k < 90 ? standing : lifted, k / 60.0, {}, nullptr);
    std::this_thread::sleep_for(std::chrono::microseconds(16667));
  }
  REQUIRE(d.wait(std::chrono::seconds(30)) == 0);
  INFO(d.output());

  // The arm rises once the filter's look-ahead (250 ms, the default) has
  // passed; the stream's own path (the jitter buffer's 30 ms and the
  // physics) takes under 100 ms without the stage.
  const auto rot = [](const sim::Quat& q) { return std::array<double, 4>{q.x(), q.y(), q.z(), q.w()}; };
  const std::array<double, 4> want = rot(lifted.bone[sim::index(sim::Bone::LeftUpperArm)].rot);
  std::int64_t risen_us = -1;
  double held_err = 0.0;
  int held_n = 0;
  for (const auto& m : capture.messages()) {
    if (m.path != "/VMC/Ext/Bone/Pos" || m.text != "LeftUpperArm" || m.arrival_us < lift_us) continue;
    const double err = angle_between({m.numbers[3], m.numbers[4], m.numbers[5], m.numbers[6]}, want);
    if (risen_us < 0 && err < 0.4) risen_us = m.arrival_us;
    if (m.arrival_us > lift_us + 800'000 && m.arrival_us < lift_us + 1'400'000) {
      held_err = std::max(held_err, err);
      ++held_n;
    }
  }
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  const std::string note = j["tracker_balance"].get<std::string>();
  MESSAGE("balance: " << note << "; the arm half-way up " << (risen_us - lift_us) / 1000
                      << " ms after the performer's; then off it by at most " << held_err << " rad");
  CHECK(note.find("online on the VMC performer stream") != std::string::npos);
  // The sender's 60 Hz as measured (a loaded machine sends late, never early),
  // and the look-ahead in its frames: 250 ms.
  std::smatch found;
  REQUIRE(std::regex_search(note, found, std::regex("the sender at ([0-9.]+) Hz .* look-ahead ([0-9]+) frames")));
  const double rate_hz = std::stod(found[1]);
  CHECK(rate_hz > 40.0);
  CHECK(rate_hz < 65.0);
  CHECK(std::abs(std::stoi(found[2]) - 0.25 * rate_hz) <= 0.55);  // rounded, from the rate printed to 0.1 Hz
  REQUIRE(risen_us > 0);
  CHECK(risen_us - lift_us >= 230'000);
  CHECK(risen_us - lift_us < 600'000);
  REQUIRE(held_n > 10);
  CHECK(held_err < 0.1);  // the stage does not touch the arms
}

TEST_CASE("tonusd: the control API spawns gifts, overrides and releases the stiffness, reports status, tonus ctl too") {
  VmcCapture capture;
  Process d(TONUSD,
            {"--no-realtime", "--no-viewer", "--seconds", "10", "--tracker", "none", "--control-port", "0",
             "--vmc-port", std::to_string(capture.port()), "--vmc-rate", "200"},
            temp_path("control.log"));
  REQUIRE(d.started());
  const int port = port_in_log(d, "control: http://127\\.0\\.0\\.1:([0-9]+)/status");
  REQUIRE(port > 0);
  control::ControlClient client("127.0.0.1", port, 2);
  control::ClientReply st;
  for (int i = 0; i < 100; ++i) {  // the simulator starts and connects (slower under a sanitizer)
    st = client.status();
    if (st.status == 200 && st.body["band"]["connected"].get<bool>()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  REQUIRE(st.status == 200);
  CHECK(st.body["band"]["connected"].get<bool>());
  CHECK(st.body["ticks"].get<double>() > 0);

  control::GiftRequest cube;
  cube.kind = control::GiftKind::cube;
  cube.bone = sim::Bone::LeftHand;
  const control::ClientReply g = client.gift(cube);
  CHECK(g.status == 202);
  CHECK(g.body["bone"] == "LeftHand");

  const std::int64_t override_us = test::steady_us();
  CHECK(client.set_stiffness(control::Levels{0.95, 0.95, 0.95, 0.95}).status == 202);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  CHECK(client.status().body["objects"].get<int>() == 1);
  const std::int64_t release_us = test::steady_us();
  CHECK(client.set_stiffness(std::nullopt).status == 202);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  CHECK(client.calibrate(control::CalibrationCommand::rest).status == 200);  // the simulated band starts a phase
  CHECK(client.calibrate(control::CalibrationCommand::abort).status == 200);

  // The same through `tonus ctl`, as a user types it.
  Process ctl(TONUS_TOOL, {"ctl", "--port", std::to_string(port), "clear"}, temp_path("ctl.log"));
  CHECK(ctl.wait(std::chrono::seconds(10)) == 0);
  Process unreachable(TONUS_TOOL, {"ctl", "--port", "1", "status"}, temp_path("ctl2.log"));
  CHECK(unreachable.wait(std::chrono::seconds(10)) == 2);
  REQUIRE(d.wait(std::chrono::seconds(30)) == 0);
  INFO(d.output());
  CHECK(d.output().find("gift 1: a cube at the LeftHand") != std::string::npos);

  // The override shows on the wire within 100 ms (rate limit 10/s from the band's level), then the band's again.
  std::int64_t overridden_us = -1, released_us = -1;
  for (const auto& m : capture.messages()) {
    if (m.path != "/tonus/Stiffness" || m.numbers.size() != 4) continue;
    const double lo = *std::min_element(m.numbers.begin(), m.numbers.end());
    if (overridden_us < 0 && m.arrival_us > override_us && lo > 0.94) overridden_us = m.arrival_us;
    if (released_us < 0 && m.arrival_us > release_us + 200'000 && lo < 0.9) released_us = m.arrival_us;
  }
  REQUIRE(overridden_us > 0);
  CHECK(overridden_us - override_us < 300'000);  // a command and a rate-limited step, on a loaded machine
  CHECK(released_us > 0);
}

TEST_CASE("tonusd: a bad config names the key and the value, and nothing starts") {
  const struct {
    const char* toml;
    const char* expect;
  } cases[] = {
      {"[output]\nrate_hz = 1000\n", "output.rate_hz = 1000: must be 1..200"},
      {"[band]\nsource = \"bluetooth\"\n", "band.source = \"bluetooth\""},
      {"[tracker]\nlisten_prot = 1\n", "tracker.listen_prot: unknown key"},
  };
  int k = 0;
  for (const auto& c : cases) {
    const std::string cfg = write_file("bad" + std::to_string(k) + ".toml", c.toml);
    Process p(TONUSD, {"--no-realtime", "--no-viewer", "--config", cfg, "--seconds", "5"},
              temp_path("bad" + std::to_string(k++) + ".log"));
    const int rc = p.wait(std::chrono::seconds(10));
    INFO(p.output());
    CHECK(rc == 2);
    CHECK(p.output().find(c.expect) != std::string::npos);
    CHECK(p.output().find("physics:") == std::string::npos);  // no thread was started
  }
  // A port in use is a start-up error too (exit 1), naming the keys.
  VmcCapture busy;  // holds a UDP port on 127.0.0.1
  Process p(TONUSD,
            {"--no-realtime", "--tracker", "vmc", "--listen-port", std::to_string(busy.port()), "--seconds", "5",
             "--no-control", "--no-viewer"},
            temp_path("busy.log"));
  const int rc = p.wait(std::chrono::seconds(10));
  INFO(p.output());
  CHECK(rc == 1);
  CHECK(p.output().find("tracker.listen_port = " + std::to_string(busy.port())) != std::string::npos);
  // --print-config reads back.
  Process pc(TONUSD, {"--print-config"}, temp_path("printed.toml"));
  REQUIRE(pc.wait(std::chrono::seconds(10)) == 0);
  Process again(TONUSD, {"--config", temp_path("printed.toml"), "--print-config"}, temp_path("printed2.toml"));
  REQUIRE(again.wait(std::chrono::seconds(10)) == 0);
  CHECK(test::read_file(temp_path("printed.toml")) == test::read_file(temp_path("printed2.toml")));
}

TEST_CASE("tonusd --vrm: a file that is not a usable .vrm stops tonusd before anything starts") {
  const std::string text = write_file("avatar-text.vrm", "{\"asset\": {\"version\": \"2.0\"}}");
  const struct {
    std::vector<std::string> args;
    const char* expect;
  } cases[] = {
      {{"--vrm", "/nonexistent/alice.vrm"}, "viewer.vrm = \"/nonexistent/alice.vrm\": no such file"},
      {{"--vrm", text}, "not a glTF binary"},
      {{"--config", write_file("vrm.toml", "[viewer]\nvrm = \"/nonexistent/bob.vrm\"\n")},
       "viewer.vrm = \"/nonexistent/bob.vrm\": no such file"},
  };
  int k = 0;
  for (const auto& c : cases) {
    std::vector<std::string> args{"--no-realtime", "--seconds", "5"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    Process p(TONUSD, args, temp_path("vrm" + std::to_string(k++) + ".log"));
    const int rc = p.wait(std::chrono::seconds(10));
    INFO(p.output());
    CHECK(rc == 2);
    CHECK(p.output().find(c.expect) != std::string::npos);
    CHECK(p.output().find("viewer: http") == std::string::npos);  // nothing was started
  }
  // Without the viewer the avatar is not needed, so not checked.
  Process off(TONUSD, {"--no-viewer", "--vrm", "/nonexistent/alice.vrm", "--print-config"}, temp_path("vrm-off.toml"));
  CHECK(off.wait(std::chrono::seconds(10)) == 0);
}

TEST_CASE("tonusd: a candump log of a band session replays as the band") {
  const std::string log = temp_path("band.candump");
  Process sim(TONUS_BAND_SIM,
              {"--synthetic", "step", "--step-from", "0.8", "--step-to", "0.8", "--seconds", "4", "--candump", log,
               "--fast", "--quiet"},
              temp_path("simdump.log"));
  REQUIRE(sim.wait(std::chrono::seconds(30)) == 0);
  const nlohmann::json j =
      run_tonusd({"--seconds", "3", "--band", "candump", "--band-candump", log, "--tracker", "none"}, "candump");
  CHECK(j["band_reports_received"].get<double>() > 300);  // the log's reports, at its own pace
  CHECK(j["band_reports_lost"].get<double>() == 0);
  CHECK(j["stiffness_max"]["right_arm"].get<double>() > 0.5);
}

TEST_CASE("tonusd: VMC trackers (a headset and two controllers) calibrate from a T-pose and drive the arms by IK") {
  VmcCapture capture;
  Process d(TONUSD,
            {"--no-realtime", "--seconds", "5", "--band", "none", "--tracker", "vmc", "--vmc-mode", "trackers",
             "--listen-port", "0", "--vmc-port", std::to_string(capture.port()), "--vmc-rate", "100", "--no-control",
             "--no-viewer"},
            temp_path("trackers.log"));
  REQUIRE(d.started());
  const int listen_port = port_in_log(d, "mode on 127\\.0\\.0\\.1:([0-9]+)");
  REQUIRE(listen_port > 0);
  lo_address to = lo_address_new("127.0.0.1", std::to_string(listen_port).c_str());
  // Internal frame (Z up, facing +X, left +Y) to Unity's (Y up, facing +Z, right +X): (x, y, z) -> (-y, z, x).
  const auto send = [&](const char* path, const char* serial, double x, double y, double z) {
    // Varargs: liblo reads each "f" as a double (C promotes floats) and sends it as a float.
    lo_send(to, path, "sfffffff", serial, -y, z, x, 0.0, 0.0, 0.0, 1.0);
  };
  // 1.5 s standing in a T-pose, then 1.5 s with the right hand brought forward and down to the belly.
  std::int64_t moved_us = 0;
  for (int k = 0; k < 180; ++k) {
    const bool moved = k >= 90;
    if (moved && moved_us == 0) moved_us = test::steady_us();
    send("/VMC/Ext/Hmd/Pos", "HMD", 0.0, 0.0, 1.62);
    send("/VMC/Ext/Con/Pos", "LEFT", 0.0, 0.80, 1.42);
    if (moved) {
      send("/VMC/Ext/Con/Pos", "RIGHT", 0.35, -0.10, 1.05);
    } else {
      send("/VMC/Ext/Con/Pos", "RIGHT", 0.0, -0.80, 1.42);
    }
    std::this_thread::sleep_for(std::chrono::microseconds(16667));
  }
  lo_address_free(to);
  REQUIRE(d.wait(std::chrono::seconds(30)) == 0);
  INFO(d.output());
  CHECK(d.output().find("calibrated from the first full frame") != std::string::npos);
  // The right upper arm's direction (its rest one: Unity +X, the avatar's right), whatever its twist: near
  // the rest while the hand is out, swung well away once the hand comes in.
  const auto swing = [](const std::vector<double>& n) {
    const sim::Quat q(n[6], n[3], n[4], n[5]);  // w x y z from the message's x y z w
    const sim::Vec3 dir = q.normalized() * sim::Vec3::UnitX();
    return std::acos(std::clamp(dir.x(), -1.0, 1.0));
  };
  double rest_turn = 0.0, moved_turn = 0.0;
  int rest_n = 0, moved_n = 0;
  for (const auto& m : capture.messages()) {
    if (m.path != "/VMC/Ext/Bone/Pos" || m.text != "RightUpperArm") continue;
    const double turn = swing(m.numbers);
    if (m.arrival_us > moved_us - 600'000 && m.arrival_us < moved_us - 100'000) {
      rest_turn = std::max(rest_turn, turn);
      ++rest_n;
    }
    if (m.arrival_us > moved_us + 900'000 && m.arrival_us < moved_us + 1'400'000) {
      moved_turn = std::min(moved_n == 0 ? 10.0 : moved_turn, turn);
      ++moved_n;
    }
  }
  MESSAGE("right upper arm: swung at most " << rest_turn << " rad from the T-pose with the hand out, at least "
                                            << moved_turn << " rad with it at the belly");
  REQUIRE(rest_n > 10);
  REQUIRE(moved_n > 10);
  CHECK(rest_turn < 0.6);  // the clavicle's share and the shoulder's height leave the arm a little off level
  CHECK(moved_turn > rest_turn + 0.8);
}
