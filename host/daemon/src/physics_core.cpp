#include "tonus/host/daemon/physics_core.hpp"

#include <algorithm>

#include "tonus/host/daemon/recorder.hpp"
#include "tonus/host/daemon/recording_format.hpp"

namespace tonus::daemon {

std::string_view to_string(GiftKind k) { return k == GiftKind::ball ? "ball" : "cube"; }

std::unique_ptr<PhysicsCore> PhysicsCore::create(const sim::Model& model, const PhysicsCoreConfig& config,
                                                 std::string& error) {
  if (error = validate(config.stiffness); !error.empty()) return nullptr;
  if (error = validate(config.pose); !error.empty()) return nullptr;
  avatar::AvatarController::Created c = avatar::AvatarController::create(model, config.avatar);
  if (!c) {
    error = c.error;
    return nullptr;
  }
  return std::unique_ptr<PhysicsCore>(new PhysicsCore(model, config, std::move(*c.controller)));
}

PhysicsCore::PhysicsCore(const sim::Model& model, const PhysicsCoreConfig& config, avatar::AvatarController controller)
    : model_(&model),
      config_(config),
      controller_(std::make_unique<avatar::AvatarController>(std::move(controller))),
      stiffness_(config.stiffness),
      pose_buffer_(model, config.pose) {
  start_standing();
}

void PhysicsCore::start_standing() {
  // Start where the pose buffer starts (neutral, standing), at the safe stiffness.
  Qpos start{};
  pose_buffer_.sample(0, start);
  input_.reference.qpos = start;
  controller_->resync(input_.reference);
  controller_->set_stiffness_now(config_.stiffness.safe_default);
}

bool PhysicsCore::restart(std::string& error) {
  avatar::AvatarController::Created c = avatar::AvatarController::create(*model_, config_.avatar);
  if (!c) {
    error = c.error;
    return false;
  }
  controller_ = std::make_unique<avatar::AvatarController>(std::move(*c.controller));
  stiffness_ = StiffnessInput(config_.stiffness);
  pose_buffer_ = PoseBuffer(*model_, config_.pose);
  BandSample b;
  while (band_.try_dequeue(b)) {
  }
  PoseSample p;
  while (pose_.try_dequeue(p)) {
  }
  Command cmd;
  while (commands_.try_dequeue(cmd)) {
  }
  override_.reset();
  input_ = avatar::TickInput{};
  reactions_ = {};
  object_ids_ = {};
  object_kinds_ = {};
  band_arrival_us_ = 0;
  band_live_ = false;
  pose_state_ = PoseState::none;
  stats_ = CoreStats{};
  start_standing();
  return true;
}

bool PhysicsCore::push_command(const Command& c) {
  const std::lock_guard<std::mutex> lock(command_producers_);
  return commands_.try_enqueue(c) || count_drop(command_dropped_);
}

Event PhysicsCore::event(Event::Kind kind) const {
  Event e;
  e.kind = kind;
  e.time_s = controller_->output().time_s;
  return e;
}

void PhysicsCore::emit(const Event& e) {
  if (!events_.try_enqueue(e)) ++stats_.events_dropped;
}

sim::Vec3 PhysicsCore::bone_offset(sim::Bone b) const {
  const std::size_t i = sim::index(b);
  return controller_->sim_b().xcom[i] - controller_->sim_a().xcom[i];
}

int PhysicsCore::group_of(sim::Bone b) const { return config_.avatar.stiffness.bone_group[sim::index(b)]; }

double PhysicsCore::group_stiffness(sim::Bone b) const {
  const int g = group_of(b);
  if (g < 0) return 0.0;
  return controller_->mapper().applied()[static_cast<std::size_t>(g)];
}

double PhysicsCore::group_hz(sim::Bone b) const {
  const int g = group_of(b);
  if (g < 0) return config_.avatar.stiffness.ungrouped.min_hz;
  const auto gi = static_cast<std::size_t>(g);
  return controller_->mapper().frequency_hz(gi, controller_->mapper().applied()[gi]);
}

void PhysicsCore::spawn(const Command& c) {
  const avatar::SpawnResult r =
      c.gift == GiftKind::ball ? controller_->throw_ball(c.ball) : controller_->drop_cube(c.cube);
  const sim::Bone bone = c.gift == GiftKind::ball ? c.ball.target : c.cube.target;
  Event e = event(Event::Kind::gift_spawned);
  e.id = c.id;
  e.gift = c.gift;
  e.bone = bone;
  if (!r.ok()) {
    e.kind = Event::Kind::gift_refused;
    e.error = r.error;
    emit(e);
    return;
  }
  const auto slot = static_cast<std::size_t>(r.id.slot);
  if (slot < object_ids_.size()) {
    object_ids_[slot] = c.id;
    object_kinds_[slot] = c.gift;
  }
  e.stiffness = group_stiffness(bone);
  e.natural_hz = group_hz(bone);
  emit(e);
  const auto free_slot =
      std::find_if(reactions_.begin(), reactions_.end(), [](const Reaction& x) { return !x.active; });
  if (free_slot == reactions_.end()) {
    ++stats_.reactions_untracked;
    return;
  }
  *free_slot = Reaction{true, c.id, r.id, c.gift, bone, e.time_s, e.stiffness, e.natural_hz, bone_offset(bone), 0.0};
}

void PhysicsCore::apply(const Command& c) {
  ++stats_.commands;
  Event e = event(Event::Kind::gifts_cleared);
  e.id = c.id;
  switch (c.kind) {
    case Command::Kind::gift: spawn(c); return;
    case Command::Kind::clear_gifts:
      controller_->clear_gifts();
      e.kind = Event::Kind::gifts_cleared;
      break;
    case Command::Kind::stiffness_override:
      override_ = c.levels;
      for (double& v : *override_) v = std::isfinite(v) ? std::clamp(v, 0.0, 1.0) : 0.5;
      e.kind = Event::Kind::stiffness_override;
      e.levels = *override_;
      break;
    case Command::Kind::stiffness_release:
      override_.reset();
      e.kind = Event::Kind::stiffness_release;
      break;
  }
  emit(e);
}

void PhysicsCore::track_reactions() {
  const double now_s = controller_->output().time_s;
  for (Reaction& r : reactions_) {
    if (!r.active) continue;
    const auto slot = static_cast<std::size_t>(r.gift.slot);
    const sim::Object& obj = controller_->sim_b().objects[slot];
    const bool alive = obj.active && obj.generation == r.gift.generation;
    if (alive) r.peak_m = std::max(r.peak_m, (bone_offset(r.bone) - r.baseline).norm());
    if (!alive || now_s - r.start_s >= config_.reaction_window_s) {
      Event e = event(Event::Kind::gift_reaction);
      e.id = r.id;
      e.gift = r.kind;
      e.bone = r.bone;
      e.stiffness = r.stiffness;
      e.natural_hz = r.natural_hz;
      e.peak_deflection_m = r.peak_m;
      emit(e);
      r.active = false;
    }
  }
}

void PhysicsCore::publish(std::int64_t now_us) {
  const avatar::TickOutput& out = controller_->output();
  Snapshot& s = snapshots_.write_slot();
  s.tick = stats_.ticks;
  s.time_s = out.time_s;
  s.tick_host_us = now_us;
  s.qpos = out.qpos;
  s.stiffness = out.stiffness;
  s.band_live = band_live_;
  s.override_active = override_.has_value();
  s.pose_state = pose_state_;
  s.band_arrival_us = band_arrival_us_;
  s.nobjects = 0;
  const sim::Data& b = controller_->sim_b();
  for (std::size_t k = 0; k < b.objects.size(); ++k) {
    const sim::Object& o = b.objects[k];
    if (!o.active) continue;
    ObjectView& v = s.objects[static_cast<std::size_t>(s.nobjects++)];
    v.id = object_ids_[k];
    v.slot = static_cast<int>(k);
    v.kind = object_kinds_[k];
    v.size_m = o.shape.type == sim::ShapeType::box ? 2.0 * o.shape.half_extents_m.x() : o.shape.radius_m;
    v.pos = o.pos;
    v.rot = o.quat;
  }
  std::uint64_t h = stats_.output_hash;
  h = recording::hash_bytes(h, s.qpos.data(), sizeof(double) * static_cast<std::size_t>(model_->nq));
  h = recording::hash_bytes(h, s.stiffness.data(), sizeof s.stiffness);
  for (int i = 0; i < s.nobjects; ++i) {
    const ObjectView& v = s.objects[static_cast<std::size_t>(i)];
    h = recording::hash_bytes(h, v.pos.data(), 3 * sizeof(double));
    h = recording::hash_bytes(h, v.rot.coeffs().data(), 4 * sizeof(double));
  }
  stats_.output_hash = h;
  status_snapshots_.write_slot() = s;
  snapshots_.publish();
  status_snapshots_.publish();
  if (config_.viewer_every_ticks > 0 && stats_.ticks % static_cast<std::uint64_t>(config_.viewer_every_ticks) == 0) {
    publish_viewer(s);
  }
}

void PhysicsCore::publish_viewer(const Snapshot& s) {
  ViewerSnapshot& v = viewer_snapshots_.write_slot();
  v.base = s;
  v.reference = controller_->sim_a().qpos;
  const sim::Data& b = controller_->sim_b();
  v.contacts_total = b.ncon;
  // The strongest first when there are more than the viewer takes (no allocation: indices on the stack).
  std::array<int, sim::kMaxContacts> order{};
  const auto n = static_cast<std::size_t>(std::clamp(b.ncon, 0, static_cast<int>(sim::kMaxContacts)));
  for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<int>(i);
  const std::size_t keep = std::min(n, kViewerContacts);
  std::partial_sort(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(keep),
                    order.begin() + static_cast<std::ptrdiff_t>(n), [&b](int x, int y) {
                      return b.contacts[static_cast<std::size_t>(x)].force_world.squaredNorm() >
                             b.contacts[static_cast<std::size_t>(y)].force_world.squaredNorm();
                    });
  using Kind = sim::ContactSide::Kind;
  for (std::size_t i = 0; i < keep; ++i) {
    const sim::Contact& c = b.contacts[static_cast<std::size_t>(order[i])];
    ContactView& cv = v.contacts[i];
    cv.pos = c.pos;
    // force_world acts on side a: the arrow shows the force on the avatar or the object, not on the ground.
    cv.force_n = c.a.kind == Kind::ground ? sim::Vec3(-c.force_world) : c.force_world;
    cv.avatar_on_ground =
        (c.a.kind == Kind::ground && c.b.kind == Kind::body) || (c.b.kind == Kind::ground && c.a.kind == Kind::body);
  }
  v.ncontacts = static_cast<int>(keep);
  viewer_snapshots_.publish();
}

void PhysicsCore::close_interval(double& latency_p50_us, double& latency_p99_us) {
  latency_p50_us = interval_latency_.quantile_us(0.5);
  latency_p99_us = interval_latency_.quantile_us(0.99);
  interval_latency_.clear();
}

void PhysicsCore::tick(std::int64_t now_us) {
  // read (and record what was read)
  Recorder* const rec = recorder_ != nullptr && recorder_->active() ? recorder_ : nullptr;
  std::uint32_t bands = 0, poses = 0, commands = 0;
  BandSample band;
  while (band_.try_dequeue(band)) {
    ++stats_.band_samples;
    ++bands;
    if (rec != nullptr) rec->band(band);
    stiffness_.on_report(band.arrival_us, band.levels);
    band_arrival_us_ = std::max(band_arrival_us_, band.arrival_us);
    if (band.sampled_host_us > 0) {
      band_latency_.add(static_cast<double>(now_us - band.sampled_host_us));
      interval_latency_.add(static_cast<double>(now_us - band.sampled_host_us));
    }
  }
  PoseSample* pose = nullptr;
  while ((pose = pose_.peek()) != nullptr) {
    ++stats_.pose_samples;
    ++poses;
    if (rec != nullptr) rec->pose(*pose);
    pose_buffer_.push(*pose);
    pose_.pop();
  }
  Command cmd;
  while (commands_.try_dequeue(cmd)) {
    ++commands;
    if (rec != nullptr) rec->command(cmd);
    apply(cmd);
  }

  const PoseState ps = pose_buffer_.sample(now_us, input_.reference.qpos);
  input_.reference.has_velocity = false;
  if (ps != pose_state_) {
    Event e = event(Event::Kind::tracker_state);
    e.pose_state = ps;
    emit(e);
    pose_state_ = ps;
  }
  const bool live = stiffness_.live(now_us);
  if (live != band_live_ && stiffness_.ever_received()) {
    emit(event(live ? Event::Kind::band_live : Event::Kind::band_stale));
  }
  band_live_ = live;
  input_.stiffness = override_ ? *override_ : stiffness_.at(now_us);

  // update
  const avatar::TickOutput& out = controller_->tick(input_);
  ++stats_.ticks;
  for (std::size_t g = 0; g < out.stiffness.size(); ++g) {
    stats_.stiffness_min[g] = std::min(stats_.stiffness_min[g], out.stiffness[g]);
    stats_.stiffness_max[g] = std::max(stats_.stiffness_max[g], out.stiffness[g]);
  }
  if ((out.flags & (avatar::kResetA | avatar::kResetB)) != 0) {
    ++stats_.avatar_resets;
    Event e = event(Event::Kind::avatar_reset);
    e.flags = out.flags;
    emit(e);
  }
  if ((out.flags & (avatar::kReferenceJump | avatar::kResetB | avatar::kResetA)) != 0) {
    // A and B were put back on the reference: the reactions measure from here.
    for (Reaction& r : reactions_) {
      if (r.active) r.baseline = bone_offset(r.bone);
    }
  }
  if ((out.flags & avatar::kReferenceJump) != 0) {
    emit(event(Event::Kind::reference_jump));
  }
  track_reactions();

  // write
  publish(now_us);
  if (rec != nullptr) rec->tick(now_us, stats_.ticks, stats_.output_hash, bands, poses, commands);
}

}  // namespace tonus::daemon
