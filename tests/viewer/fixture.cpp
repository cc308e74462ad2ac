// tonus-viewer-fixture: the live viewer's server with synthetic but plausible
// data, for the browser tests and for looking at the page without tonusd.
//
// The scene is tonus's humanoid as tonusd describes it (make_viewer_scene: its
// bones, collision shapes and stiffness groups); each frame poses it by the
// physics core's own forward kinematics: a gentle sway, arms half lowered,
// the reference a little ahead of the avatar. Stiffness swells and ebbs per group. The page's requests go through
// the control API's own router (tonus::control::route) to a small handler,
// exactly as tonusd's will: a thrown ball or a dropped cube appears in the
// next frames, flies to its bone and falls to the ground.
//
//   tonus-viewer-fixture [--port N] [--seconds S] [--rate HZ] [--playback] [--web-root DIR] [--vrm FILE]
//
// Prints "viewer: http://127.0.0.1:PORT/" once listening (the line tonusd
// prints too), then serves until --seconds pass (0: until SIGINT/SIGTERM).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <mutex>
#include <numbers>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "tonus/host/control/api.hpp"
#include "tonus/host/control/router.hpp"
#include "tonus/host/daemon/viewer_feed.hpp"
#include "tonus/host/viewer/server.hpp"
#include "tonus/sim/data.hpp"
#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/step.hpp"

namespace {

namespace sim = tonus::sim;
namespace tv = tonus::viewer;
namespace tc = tonus::control;
using Clock = std::chrono::steady_clock;
constexpr double kPi = std::numbers::pi;

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int /*signal*/) { g_stop = true; }

tv::Vec3 vec(const sim::Vec3& v) { return {v.x(), v.y(), v.z()}; }
tv::QuatXyzw quat(const sim::Quat& q) { return {q.x(), q.y(), q.z(), q.w()}; }

struct Gift {
  std::uint32_t id = 0;
  bool ball = true;
  sim::Bone bone = sim::Bone::Chest;
  double size_m = 0.11;  // a ball's radius, a cube's edge (frame.hpp)
  double height_m = 0.4;
  double born_s = 0.0;
  double lifetime_s = 8.0;
};

// The page's requests, through the control API's router, as tonusd's are.
class FixtureHandler final : public tc::Handler {
 public:
  tc::Reply spawn_gift(const tc::GiftRequest& request) override {
    const std::lock_guard<std::mutex> lock(mutex_);
    Gift g;
    g.id = next_id_++;
    g.ball = request.kind == tc::GiftKind::ball;
    g.bone = request.bone.value_or(g.ball ? sim::Bone::Chest : sim::Bone::RightHand);
    g.size_m = request.size_m.value_or(g.ball ? 0.22 : 0.1) * (g.ball ? 0.5 : 1.0);  // the API's diameter
    g.height_m = request.height_m.value_or(0.4);
    g.born_s = now_s_;
    g.lifetime_s = request.lifetime_s.value_or(8.0);
    if (g.lifetime_s <= 0.0) g.lifetime_s = 1e9;
    gifts_.push_back(g);
    if (gifts_.size() > 16) gifts_.erase(gifts_.begin());
    return tc::Reply::ok({{"id", g.id}}, 202);  // as tonusd: queued for the next tick
  }
  tc::Reply clear_gifts() override {
    const std::lock_guard<std::mutex> lock(mutex_);
    const std::size_t n = gifts_.size();
    gifts_.clear();
    return tc::Reply::ok({{"cleared", n}});
  }
  tc::Reply set_stiffness_override(const std::optional<tc::Levels>& levels) override {
    const std::lock_guard<std::mutex> lock(mutex_);
    override_ = levels;
    return tc::Reply::ok({{"override", levels ? nlohmann::json(*levels) : nlohmann::json(nullptr)}});
  }
  tc::Reply calibrate(tc::CalibrationCommand command) override {
    return tc::Reply::ok({{"calibration", std::string(tc::to_string(command))}}, 202);
  }
  tc::Reply status() override {
    const std::lock_guard<std::mutex> lock(mutex_);
    return tc::Reply::ok({{"state", "running"}, {"fixture", true}, {"gifts", gifts_.size()}, {"time_s", now_s_}});
  }

  // The main loop's view (under the lock).
  void advance(double now_s, std::vector<Gift>& gifts, std::optional<tc::Levels>& override_levels) {
    const std::lock_guard<std::mutex> lock(mutex_);
    now_s_ = now_s;
    std::erase_if(gifts_, [now_s](const Gift& g) { return now_s - g.born_s > g.lifetime_s || now_s < g.born_s; });
    gifts = gifts_;
    override_levels = override_;
  }

 private:
  std::mutex mutex_;
  std::vector<Gift> gifts_;
  std::optional<tc::Levels> override_;
  std::uint32_t next_id_ = 1;
  double now_s_ = 0.0;
};

// Poses the humanoid at time t (s): the root sways, the spine bends a little,
// the arms hang half lowered and swing, the knees give.
void pose(const sim::Model& model, sim::Data& data, double t) {
  data.qpos = model.qpos0;
  auto set_ball = [&](sim::Bone b, const sim::Quat& q) {
    const sim::Body& body = model.bodies[sim::index(b)];
    if (body.joint != sim::JointType::ball) return;
    const auto a = static_cast<std::size_t>(body.qpos_adr);
    data.qpos[a] = q.w();
    data.qpos[a + 1] = q.x();
    data.qpos[a + 2] = q.y();
    data.qpos[a + 3] = q.z();
  };
  auto set_hinge = [&](sim::Bone b, double angle) {
    const sim::Body& body = model.bodies[sim::index(b)];
    if (body.joint == sim::JointType::hinge) data.qpos[static_cast<std::size_t>(body.qpos_adr)] = angle;
  };
  auto about = [](double angle, const sim::Vec3& axis) { return sim::Quat(Eigen::AngleAxisd(angle, axis)); };

  const sim::Body& root = model.bodies[0];
  const auto r = static_cast<std::size_t>(root.qpos_adr);
  const double sway = std::sin(2.0 * kPi * 0.35 * t);
  data.qpos[r + 1] += 0.03 * sway;                                   // side to side
  data.qpos[r + 2] -= 0.02 * (1.0 - std::cos(2.0 * kPi * 0.7 * t));  // a little dip
  const sim::Quat yaw = about(0.12 * std::sin(2.0 * kPi * 0.2 * t), sim::Vec3::UnitZ());
  data.qpos[r + 3] = yaw.w();
  data.qpos[r + 4] = yaw.x();
  data.qpos[r + 5] = yaw.y();
  data.qpos[r + 6] = yaw.z();

  set_ball(sim::Bone::Spine, about(0.08 * std::sin(2.0 * kPi * 0.25 * t), sim::Vec3::UnitY()));
  set_ball(sim::Bone::Chest, about(-0.05 * sway, sim::Vec3::UnitX()));
  set_ball(sim::Bone::Head, about(0.25 * std::sin(2.0 * kPi * 0.15 * t), sim::Vec3::UnitZ()));
  const double lower = 1.05 + 0.2 * std::sin(2.0 * kPi * 0.3 * t);
  set_ball(sim::Bone::RightUpperArm, about(lower, sim::Vec3::UnitX()) * about(0.3 * sway, sim::Vec3::UnitZ()));
  set_ball(sim::Bone::LeftUpperArm, about(-lower, sim::Vec3::UnitX()) * about(-0.3 * sway, sim::Vec3::UnitZ()));
  set_hinge(sim::Bone::RightLowerArm, 0.5 + 0.3 * std::sin(2.0 * kPi * 0.4 * t));
  set_hinge(sim::Bone::LeftLowerArm, 0.5 + 0.3 * std::cos(2.0 * kPi * 0.4 * t));
  const double knee = 0.12 + 0.1 * (1.0 - std::cos(2.0 * kPi * 0.7 * t));
  set_hinge(sim::Bone::RightLowerLeg, knee);
  set_hinge(sim::Bone::LeftLowerLeg, knee);
  sim::forward_kinematics(model, data);
}

std::vector<tv::BonePose> bone_poses(const sim::Data& data) {
  std::vector<tv::BonePose> out;
  for (std::size_t i = 0; i < sim::kBoneCount; ++i) out.push_back({vec(data.xbody[i].pos), quat(data.xquat[i])});
  return out;
}

// Where a gift is at `t`: a ball flies in from the front to its bone in
// 0.4 s, a cube falls from above onto it; then both fall to the ground.
struct GiftState {
  tv::Vec3 pos;
  bool hit_now = false;  // just arrived at the bone (a contact arrow)
};
GiftState gift_state(const Gift& g, const sim::Vec3& bone_pos, double t) {
  const double age = t - g.born_s;
  const double rest_z = g.ball ? g.size_m : 0.5 * g.size_m;
  const double approach = g.ball ? 0.4 : std::sqrt(2.0 * g.height_m / 9.81);
  const sim::Vec3 start =
      g.ball ? sim::Vec3(bone_pos + sim::Vec3(1.6, 0.0, 0.35)) : sim::Vec3(bone_pos + sim::Vec3(0.0, 0.0, g.height_m));
  sim::Vec3 p;
  if (age < approach) {
    const double s = age / approach;
    p = g.ball ? sim::Vec3(start + s * (bone_pos + sim::Vec3(0.12, 0.0, 0.0) - start))
               : sim::Vec3(start - sim::Vec3(0.0, 0.0, 0.5 * 9.81 * age * age));
  } else {
    const sim::Vec3 hit =
        g.ball ? sim::Vec3(bone_pos + sim::Vec3(0.12, 0.0, 0.0)) : sim::Vec3(bone_pos + sim::Vec3(0.0, 0.0, 0.08));
    const double fall = age - approach;
    const double z = std::max(rest_z, hit.z() - 0.5 * 9.81 * fall * fall);
    const double drift = g.ball ? std::min(0.6, 0.8 * fall) : std::min(0.25, 0.3 * fall);
    p = sim::Vec3(hit.x() + drift, hit.y(), z);
  }
  return {vec(p), age >= approach && age < approach + 0.15};
}

struct Options {
  int port = 0;
  double seconds = 0.0;
  double rate_hz = 30.0;
  bool playback = false;
  std::string web_root = tv::default_web_root();
  std::string vrm;
};

int run(int argc, char** argv) {
  Options o;
  CLI::App app{"The live viewer with synthetic data (tests and a look at the page without tonusd)"};
  app.add_option("--port", o.port, "port on 127.0.0.1 (0: the system picks one)")->check(CLI::Range(0, 65535));
  app.add_option("--seconds", o.seconds, "serve this long, then exit (0: until SIGINT or SIGTERM)")
      ->check(CLI::Range(0.0, 86400.0));
  app.add_option("--rate", o.rate_hz, "frames per second")->check(CLI::Range(1.0, 240.0));
  app.add_flag("--playback", o.playback, "pretend to replay a 12 s recording: frames carry playback, seekable");
  app.add_option("--web-root", o.web_root, "the page's folder");
  app.add_option("--vrm", o.vrm, "a .vrm avatar for the page (checked as tonusd checks viewer.vrm)");
  CLI11_PARSE(app, argc, argv);
  if (!o.vrm.empty()) {
    if (const tv::VrmFileInfo info = tv::check_vrm_file(o.vrm); !info.error.empty()) {
      std::cerr << "tonus-viewer-fixture: --vrm " << o.vrm << ": " << info.error << "\n";
      return 2;
    }
  }

  const sim::BuildResult built = sim::build_humanoid(sim::HumanoidSpec{});
  if (!built) {
    std::cerr << "tonus-viewer-fixture: humanoid: " << built.error << "\n";
    return 1;
  }
  const sim::Model& model = *built.model;
  const std::unique_ptr<sim::Data> avatar = sim::make_data(model);
  const std::unique_ptr<sim::Data> reference = sim::make_data(model);

  FixtureHandler handler;
  tv::ViewerConfig config;
  config.port = o.port;
  config.web_root = o.web_root;
  config.vrm_file = o.vrm;
  tv::ViewerServer viewer(config);
  viewer.set_scene(tonus::daemon::make_viewer_scene(model, o.playback ? "replay" : "live"));  // as tonusd's
  viewer.set_request_handler([&handler](std::string_view method, std::string_view path, std::string_view body) {
    tc::Routed routed = tc::route(handler, method, path, body);
    return tv::RequestReply{routed.reply.status, std::move(routed.reply.body)};
  });

  // Playback (--playback): a 12 s "recording" that plays, pauses and seeks.
  constexpr double kDuration = 12.0;
  std::mutex playback_mutex;
  double position = 0.0;
  bool playing = true;
  if (o.playback) {
    viewer.set_playback_handler([&](const tv::PlaybackMessage& m) -> std::string {
      const std::lock_guard<std::mutex> lock(playback_mutex);
      switch (m.action) {
        case tv::PlaybackAction::play: playing = true; break;
        case tv::PlaybackAction::pause: playing = false; break;
        case tv::PlaybackAction::seek:
          if (m.position_s > kDuration) return "seek: " + std::to_string(m.position_s) + " s is past the end (12 s)";
          position = m.position_s;
          break;
      }
      return "";
    });
  }

  std::string error;
  if (!viewer.start(error)) {
    std::cerr << "tonus-viewer-fixture: " << error << "\n";
    return 1;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  std::cout << "viewer: " << viewer.url() << std::endl;  // flushed: the tests wait for this line

  const auto start = Clock::now();
  const auto period = std::chrono::duration<double>(1.0 / o.rate_hz);
  auto next = start;
  double last_wall = 0.0;
  std::vector<Gift> gifts;
  std::optional<tc::Levels> override_levels;
  std::uint64_t lost = 0;
  while (!g_stop) {
    const double wall = std::chrono::duration<double>(Clock::now() - start).count();
    if (o.seconds > 0.0 && wall >= o.seconds) break;
    double t = wall;
    std::optional<tv::PlaybackFrame> playback;
    if (o.playback) {
      const std::lock_guard<std::mutex> lock(playback_mutex);
      if (playing) position += wall - last_wall;
      if (position >= kDuration) {
        position = kDuration;
        playing = false;
      }
      t = position;
      playback = tv::PlaybackFrame{kDuration, position, playing};
    }
    last_wall = wall;
    handler.advance(wall, gifts, override_levels);

    pose(model, *avatar, t);
    pose(model, *reference, t + 0.25);
    tv::Frame f;
    f.tick = static_cast<std::uint64_t>(t * 1000.0);
    f.time_s = t;
    f.avatar = bone_poses(*avatar);
    f.reference = bone_poses(*reference);
    for (std::size_t g = 0; g < tonus::avatar::kGroupCount; ++g) {
      const double swell = 0.5 + 0.42 * std::sin(2.0 * kPi * t / 4.0 + 0.9 * static_cast<double>(g));
      f.stiffness.push_back(override_levels ? (*override_levels)[g] : swell);
    }
    f.override_active = override_levels.has_value();

    // Feet on the ground: the support polygon around both feet, the ZMP
    // under the hips, four contact forces carrying the body's weight.
    const sim::Vec3 lf = avatar->xbody[sim::index(sim::Bone::LeftFoot)].pos;
    const sim::Vec3 rf = avatar->xbody[sim::index(sim::Bone::RightFoot)].pos;
    const sim::Vec3 lt = avatar->xbody[sim::index(sim::Bone::LeftToes)].pos;
    const sim::Vec3 rt = avatar->xbody[sim::index(sim::Bone::RightToes)].pos;
    const double back = std::min(lf.x(), rf.x()) - 0.06;
    const double front = std::max(lt.x(), rt.x()) + 0.06;
    const double left = std::max(lf.y(), lt.y()) + 0.05;
    const double right = std::min(rf.y(), rt.y()) - 0.05;
    f.support = {{back, right}, {front, right}, {front, left}, {back, left}};
    const sim::Vec3 hips = avatar->xbody[0].pos;
    f.zmp = tv::Vec2{hips.x() + 0.03, hips.y()};
    const double weight = 65.0 * 9.81;
    const double share_left = std::clamp(0.5 + (hips.y() - 0.5 * (lf.y() + rf.y())) * 8.0, 0.1, 0.9);
    for (const auto& [p, share] : {std::pair{lf, share_left * 0.6}, std::pair{lt, share_left * 0.4},
                                   std::pair{rf, (1.0 - share_left) * 0.6}, std::pair{rt, (1.0 - share_left) * 0.4}}) {
      f.contacts.push_back({{p.x(), p.y(), 0.0}, {0.0, 0.0, weight * share}});
    }

    for (const Gift& g : gifts) {
      const GiftState s = gift_state(g, avatar->xbody[sim::index(g.bone)].pos, wall);
      f.objects.push_back({g.id, g.ball ? "ball" : "cube", g.size_m, s.pos, {0.0, 0.0, 0.0, 1.0}});
      if (s.hit_now) {
        f.contacts.push_back({s.pos, {g.ball ? -120.0 : 0.0, 0.0, g.ball ? 10.0 : -60.0}});
      }
    }

    f.tracker_state = std::fmod(wall, 20.0) < 18.0 ? "live" : "held";
    f.band.source = "sim";
    f.band.connected = true;
    f.band.live = true;
    f.band.calibrated = true;
    f.band.latency_p50_ms = 2.1 + 0.2 * std::sin(3.0 * wall);
    f.band.latency_p99_ms = 4.3 + 0.5 * std::sin(1.3 * wall);
    f.band.reports = static_cast<std::uint64_t>(wall * 500.0);
    if (std::fmod(wall, 7.0) < 1.0 / o.rate_hz) ++lost;
    f.band.lost = lost;
    f.metrics.ticks = static_cast<std::uint64_t>(wall * 1000.0);
    f.metrics.tick_p50_us = 84.0 + 3.0 * std::sin(wall);
    f.metrics.tick_p99_us = 190.0 + 10.0 * std::sin(0.7 * wall);
    f.metrics.tick_max_us = 420.0;
    f.metrics.tracker_rate_hz = 120.0;
    f.playback = playback;
    viewer.publish(f);

    next += std::chrono::duration_cast<Clock::duration>(period);
    std::this_thread::sleep_until(next);
  }
  const tv::ViewerStats s = viewer.stats();
  viewer.stop();
  std::cerr << "tonus-viewer-fixture: " << s.frames_published << " frames published, " << s.frames_sent << " sent, "
            << s.frames_dropped << " dropped, " << s.connections_total << " connections, " << s.requests
            << " requests, " << s.bad_messages << " bad messages\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "tonus-viewer-fixture: " << e.what() << "\n";
    return 1;
  }
}
