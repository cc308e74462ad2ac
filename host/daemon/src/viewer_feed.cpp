#include "tonus/host/daemon/viewer_feed.hpp"

#include <chrono>

#include <fmt/format.h>

#include "tonus/host/avatar/stiffness.hpp"
#include "tonus/host/balance/polygon.hpp"
#include "tonus/host/control/router.hpp"
#include "tonus/host/viewer/server.hpp"
#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::daemon {
namespace {

viewer::Vec3 v3(const sim::Vec3& v) { return {v.x(), v.y(), v.z()}; }
viewer::QuatXyzw q4(const sim::Quat& q) { return {q.x(), q.y(), q.z(), q.w()}; }

void pose_bodies(const sim::Model& model, sim::Data& scratch, const Qpos& qpos, std::vector<viewer::BonePose>& out) {
  scratch.qpos = qpos;
  sim::forward_kinematics(model, scratch);
  out.resize(static_cast<std::size_t>(model.nbody));
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i].pos = v3(scratch.xbody[i].pos);
    out[i].quat = q4(scratch.xquat[i]);
  }
}

std::string_view shape_name(sim::ShapeType t) {
  switch (t) {
    case sim::ShapeType::sphere: return "sphere";
    case sim::ShapeType::capsule: return "capsule";
    case sim::ShapeType::box: return "box";
    case sim::ShapeType::plane: return "plane";
  }
  return "?";
}

}  // namespace

viewer::Scene make_viewer_scene(const sim::Model& model, const std::string& mode) {
  viewer::Scene s;
  s.mode = mode;
  const avatar::StiffnessConfig stiffness = avatar::default_stiffness_config();
  std::vector<bool> has_shape(static_cast<std::size_t>(model.nbody), false);
  for (int g = 0; g < model.ngeom; ++g) {
    const sim::Geom& geom = model.geoms[static_cast<std::size_t>(g)];
    if (geom.shape.type == sim::ShapeType::plane) continue;
    viewer::GeomInfo gi;
    gi.bone = geom.body;
    gi.shape = std::string(shape_name(geom.shape.type));
    gi.radius_m = geom.shape.radius_m;
    gi.half_length_m = geom.shape.half_length_m;
    gi.half_extents_m = v3(geom.shape.half_extents_m);
    gi.pos = v3(geom.local.pos);
    gi.quat = q4(sim::Quat(geom.local.rot));
    s.geoms.push_back(gi);
    has_shape[static_cast<std::size_t>(geom.body)] = true;
  }
  // The rest pose (a T-pose for tonusd's humanoid): the page drives a VRM's
  // bones by their rotation from it.
  const std::unique_ptr<sim::Data> rest = sim::make_data(model);
  std::vector<viewer::BonePose> rest_poses;
  pose_bodies(model, *rest, model.qpos0, rest_poses);
  for (int b = 0; b < model.nbody; ++b) {
    const sim::Body& body = model.bodies[static_cast<std::size_t>(b)];
    viewer::BoneInfo bi;
    bi.name = std::string(body.name_view());
    bi.parent = body.parent;
    bi.rest = rest_poses[static_cast<std::size_t>(b)];
    if (const auto bone = sim::bone_from_name(bi.name)) {
      const std::int8_t g = stiffness.bone_group[sim::index(*bone)];
      bi.group = g < 0 ? -1 : static_cast<int>(static_cast<std::uint8_t>(g));
    }
    s.bones.push_back(bi);
    if (has_shape[static_cast<std::size_t>(b)]) s.gift_bones.push_back(bi.name);
  }
  for (std::size_t g = 0; g < avatar::kGroupCount; ++g) {
    s.groups.emplace_back(avatar::to_string(static_cast<avatar::Group>(g)));
  }
  s.ground_z_m = 0.0;
  s.rate_hz = 1.0 / model.timestep_s;
  return s;
}

ViewerFrameBuilder::ViewerFrameBuilder(const sim::Model& model) : model_(model), scratch_(sim::make_data(model)) {
  for (int g = 0; g < model.ngeom; ++g) {
    const sim::Geom& geom = model.geoms[static_cast<std::size_t>(g)];
    const std::string_view name = model.bodies[static_cast<std::size_t>(geom.body)].name_view();
    if (name.ends_with("Foot") || name.ends_with("Toes")) sole_geoms_.push_back(g);
  }
}

void ViewerFrameBuilder::support_from_soles(viewer::Frame& out) const {
  constexpr double kNearGround_m = 0.03;
  std::vector<balance::Vec2> points;
  for (const int g : sole_geoms_) {
    const sim::Geom& geom = model_.geoms[static_cast<std::size_t>(g)];
    const sim::Pose& x = scratch_->xgeom[static_cast<std::size_t>(g)];
    const sim::Shape& sh = geom.shape;
    const auto add = [&](const sim::Vec3& local, double radius) {
      const sim::Vec3 w = x.apply(local);
      if (w.z() - radius > kNearGround_m) return;
      for (const auto& [dx, dy] :
           {std::pair{1.0, 0.0}, std::pair{-1.0, 0.0}, std::pair{0.0, 1.0}, std::pair{0.0, -1.0}}) {
        points.emplace_back(w.x() + dx * radius, w.y() + dy * radius);
      }
    };
    if (sh.type == sim::ShapeType::box) {
      const sim::Vec3& h = sh.half_extents_m;
      for (int corner = 0; corner < 8; ++corner) {
        add(sim::Vec3((corner & 1) != 0 ? h.x() : -h.x(), (corner & 2) != 0 ? h.y() : -h.y(),
                      (corner & 4) != 0 ? h.z() : -h.z()),
            0.0);
      }
    } else if (sh.type == sim::ShapeType::capsule) {
      add(sim::Vec3(0.0, 0.0, sh.half_length_m), sh.radius_m);
      add(sim::Vec3(0.0, 0.0, -sh.half_length_m), sh.radius_m);
    } else if (sh.type == sim::ShapeType::sphere) {
      add(sim::Vec3::Zero(), sh.radius_m);
    }
  }
  for (const balance::Vec2& p : balance::convex_hull(points).vertices) out.support.push_back({p.x(), p.y()});
}

void ViewerFrameBuilder::build(const ViewerSnapshot& s, viewer::Frame& out) {
  out.tick = s.base.tick;
  out.time_s = s.base.time_s;
  pose_bodies(model_, *scratch_, s.reference, out.reference);
  pose_bodies(model_, *scratch_, s.base.qpos, out.avatar);  // last: scratch_ holds B's kinematics below
  out.objects.clear();
  for (int i = 0; i < s.base.nobjects; ++i) {
    const ObjectView& o = s.base.objects[static_cast<std::size_t>(i)];
    out.objects.push_back({o.id, std::string(to_string(o.kind)), o.size_m, v3(o.pos), q4(o.rot)});
  }
  out.contacts.clear();
  std::vector<balance::Vec2> ground_points;
  sim::Vec3 moment = sim::Vec3::Zero();
  double push_n = 0.0;
  for (int i = 0; i < s.ncontacts; ++i) {
    const ContactView& c = s.contacts[static_cast<std::size_t>(i)];
    out.contacts.push_back({v3(c.pos), v3(c.force_n)});
    if (!c.avatar_on_ground || c.force_n.z() <= 0.0) continue;
    ground_points.emplace_back(c.pos.x(), c.pos.y());
    moment += c.force_n.z() * c.pos;
    push_n += c.force_n.z();
  }
  // The whole-body centre of mass, kept for the cart-table ZMP.
  sim::Vec3 com = sim::Vec3::Zero();
  double mass = 0.0;
  for (int i = 0; i < model_.nbody; ++i) {
    const double m = model_.bodies[static_cast<std::size_t>(i)].mass_kg;
    com += m * scratch_->xcom[static_cast<std::size_t>(i)];
    mass += m;
  }
  com /= mass;
  if (coms_ > 0 && s.base.time_s <= com_t_[2]) coms_ = 0;  // time went back (a replay's seek): start again
  com_[0] = com_[1];
  com_[1] = com_[2];
  com_[2] = com;
  com_t_[0] = com_t_[1];
  com_t_[1] = com_t_[2];
  com_t_[2] = s.base.time_s;
  coms_ = std::min(coms_ + 1, 3);
  out.zmp.reset();
  out.support.clear();
  if (push_n > 1.0) {  // the body stands on the ground: the centre of pressure, exactly
    out.zmp = viewer::Vec2{moment.x() / push_n, moment.y() / push_n};
    for (const balance::Vec2& p : balance::convex_hull(ground_points).vertices) out.support.push_back({p.x(), p.y()});
  } else {
    support_from_soles(out);
    if (!out.support.empty() && coms_ == 3) {
      // Second derivative over three unevenly spaced samples.
      const double h1 = com_t_[1] - com_t_[0], h2 = com_t_[2] - com_t_[1];
      if (h1 > 0.0 && h2 > 0.0) {
        const sim::Vec3 acc = 2.0 * (h1 * com_[2] - (h1 + h2) * com_[1] + h2 * com_[0]) / (h1 * h2 * (h1 + h2));
        const double support_acc = acc.z() + 9.81;
        if (support_acc > 0.1) {
          const sim::Vec3& c = com_[1];  // the middle sample, where the difference is centred
          out.zmp = viewer::Vec2{c.x() - c.z() / support_acc * acc.x(), c.y() - c.z() / support_acc * acc.y()};
        }
      }
    }
  }
  out.stiffness.assign(s.base.stiffness.begin(), s.base.stiffness.end());
  out.override_active = s.base.override_active;
  out.band.live = s.base.band_live;
  out.tracker_state = std::string(to_string(s.base.pose_state));
}

ViewerFeed::ViewerFeed(const ViewerConfig& config, const sim::Model& model, PhysicsCore& core, std::string mode)
    : config_(config), model_(model), core_(core), mode_(std::move(mode)), builder_(model) {}

ViewerFeed::~ViewerFeed() { stop(); }

bool ViewerFeed::start(std::string& error, control::Handler* control, bool read_only, Extras extras,
                       Playback playback) {
  viewer::ViewerConfig vc;
  vc.bind_address = config_.address;
  vc.port = config_.port;
  vc.allow_remote = config_.allow_remote;
  if (!config_.web_root.empty()) vc.web_root = config_.web_root;
  vc.vrm_file = config_.vrm;
  server_ = std::make_unique<viewer::ViewerServer>(vc);
  if (control != nullptr) {
    server_->set_request_handler(
        [control, read_only](std::string_view method, std::string_view path, std::string_view body) {
          if (read_only && method != "GET" && method != "HEAD") {
            return viewer::RequestReply{409, {{"error", "replaying a recording: its inputs are the recording's"}}};
          }
          const control::Routed r = control::route(*control, method, path, body);
          return viewer::RequestReply{r.reply.status, r.reply.body};
        });
  }
  if (playback) server_->set_playback_handler(std::move(playback));
  if (!server_->start(error)) {
    error = fmt::format("viewer.address = \"{}\", viewer.port = {}: {}", config_.address, config_.port, error);
    server_.reset();
    return false;
  }
  server_->set_scene(make_viewer_scene(model_, mode_));
  extras_ = std::move(extras);
  stop_.store(false);
  thread_ = std::thread([this] { run(); });
  return true;
}

void ViewerFeed::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
  if (server_) server_->stop();
}

std::string ViewerFeed::url() const { return server_ ? server_->url() : std::string(); }
int ViewerFeed::port() const { return server_ ? server_->port() : 0; }
viewer::ViewerStats ViewerFeed::stats() const { return server_ ? server_->stats() : viewer::ViewerStats{}; }

void ViewerFeed::run() {
  const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / config_.rate_hz));
  auto next = std::chrono::steady_clock::now();
  TripleBuffer<ViewerSnapshot>& snaps = core_.viewer_snapshots();
  viewer::Frame frame;
  std::uint64_t last_tick = ~0ULL;
  while (!stop_.load()) {
    std::this_thread::sleep_until(next);
    next += period;
    if (const auto now = std::chrono::steady_clock::now(); next < now) next = now + period;
    const bool fresh = snaps.update();
    if (!fresh && last_tick != ~0ULL) {
      // Nothing new (paused replay, stalled physics): the page still gets the daemon's state.
      if (extras_) extras_(frame);
      server_->publish(frame);
      continue;
    }
    if (!fresh) continue;
    const ViewerSnapshot& s = snaps.read_slot();
    builder_.build(s, frame);
    last_tick = s.base.tick;
    if (extras_) extras_(frame);
    server_->publish(frame);
    frames_.fetch_add(1);
  }
}

}  // namespace tonus::daemon
