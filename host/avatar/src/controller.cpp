// The dual PD tick: reference checks, simulation A, the feedforward, simulation B, outputs.
#include "tonus/host/avatar/controller.hpp"

#include <algorithm>
#include <cmath>

#include "id_feedforward.hpp"
#include "reference_ops.hpp"
#include "tonus/sim/joint_limits.hpp"
#include "tonus/sim/objects.hpp"
#include "tonus/sim/step.hpp"

namespace tonus::avatar {

using std::size_t;

std::string_view to_string(Feedforward f) {
  switch (f) {
    case Feedforward::simulation: return "simulation";
    case Feedforward::inverse_dynamics: return "inverse_dynamics";
    case Feedforward::none: return "none";
  }
  return "?";
}

std::string validate(const AvatarConfig& c) {
  if (std::string e = validate(c.stiffness); !e.empty()) return e;
  const auto hz_ok = [](double f) { return std::isfinite(f) && f > 0.0 && f <= 500.0; };
  for (size_t g = 0; g < kGroupCount; ++g) {
    if (!hz_ok(c.stiff_hz[g]))
      return "stiff_hz." + std::string(to_string(static_cast<Group>(g))) + ": must be in (0, 500]";
  }
  if (!hz_ok(c.stiff_ungrouped_hz)) return "stiff_ungrouped_hz: must be in (0, 500]";
  if (!std::isfinite(c.stiff_damping_ratio) || c.stiff_damping_ratio < 0.0 || c.stiff_damping_ratio > 10.0)
    return "stiff_damping_ratio: must be in [0, 10]";
  if (!hz_ok(c.root_servo_hz)) return "root_servo_hz: must be in (0, 500]";
  if (!std::isfinite(c.jump_rad) || c.jump_rad <= 0.0) return "jump_rad: must be > 0";
  if (!std::isfinite(c.jump_m) || c.jump_m <= 0.0) return "jump_m: must be > 0";
  if (!std::isfinite(c.jump_window_s) || c.jump_window_s < 0.0) return "jump_window_s: must be >= 0";
  if (!std::isfinite(c.blowup_energy_factor) || c.blowup_energy_factor < 1.0)
    return "blowup_energy_factor: must be >= 1";
  if (!std::isfinite(c.blowup_energy_margin_j) || c.blowup_energy_margin_j <= 0.0)
    return "blowup_energy_margin_j: must be > 0";
  if (!std::isfinite(c.id_cutoff_hz) || c.id_cutoff_hz <= 0.0) return "id_cutoff_hz: must be > 0";
  if (!std::isfinite(c.gift_floor_m)) return "gift_floor_m: must be finite";
  return {};
}

struct GiftSlot {
  bool live = false;
  GiftId id;
  double expires_s = 0.0;  // 0: never
};

struct AvatarController::Impl {
  sim::StepInputs in_a;
  sim::StepInputs in_b;
  ReferencePose ref;       // this tick's, checked
  ReferencePose followed;  // what A and B follow (variant (b): delayed)
  std::array<double, sim::kMaxQpos> prev_qpos{};
  bool has_prev = false;
  std::array<int, sim::kBoneCount> bone_geom{};  // first geom of each bone, -1: none
  std::array<GiftSlot, sim::kMaxObjects> gifts{};
  std::unique_ptr<detail::IdFeedforward> id;
  std::array<double, sim::kMaxDofs> tau_id{};
  std::uint32_t contact_overflow_seen = 0;
  // The last references (a ring), to see how far the reference went within the jump window.
  std::array<std::array<double, sim::kMaxQpos>, kMaxJumpWindowTicks> window{};
  std::size_t window_ticks = 1;  // from the config
  std::size_t window_count = 0;
  std::size_t window_next = 0;
  void remember(const std::array<double, sim::kMaxQpos>& q) {
    window[window_next] = q;
    window_next = (window_next + 1) % window_ticks;
    window_count = std::min(window_count + 1, window_ticks);
  }
  [[nodiscard]] const std::array<double, sim::kMaxQpos>& oldest() const {
    return window[(window_next + window_ticks - window_count) % window_ticks];
  }
};

AvatarController::AvatarController(const sim::Model& model, const AvatarConfig& config)
    : model_(&model), config_(config), mapper_(model, config.stiffness) {}

AvatarController::~AvatarController() = default;
AvatarController::AvatarController(AvatarController&&) noexcept = default;
AvatarController& AvatarController::operator=(AvatarController&&) noexcept = default;

AvatarController::Created AvatarController::create(const sim::Model& model, const AvatarConfig& config) {
  Created made;
  if (std::string e = validate(config); !e.empty()) {
    made.error = "avatar config: " + e;
    return made;
  }
  if (model.nbody < 1 || model.bodies[0].joint != sim::JointType::free) {
    made.error = "avatar: the model's root must be a free joint (the hips)";
    return made;
  }
  AvatarController c(model, config);
  c.a_ = sim::make_data(model);
  c.b_ = sim::make_data(model);
  c.impl_ = std::make_unique<Impl>();
  Impl& im = *c.impl_;
  if (config.feedforward == Feedforward::inverse_dynamics) {
    im.id = detail::IdFeedforward::create(model, config.id_cutoff_hz, config.id_lag_ticks, made.error);
    if (!im.id) {
      made.error = "avatar config: " + made.error;
      return made;
    }
  }
  // A: contact-free (or ground only), kinematic root, stiff drives.
  c.a_->collisions.contacts = config.contacts_a != ContactsA::none;
  c.a_->collisions.objects = false;
  sim::set_root_mode(*c.a_, sim::RootMode::kinematic);
  c.b_->collisions.body_ground =
      config.body_ground_b == BodyGround::on ||
      (config.body_ground_b == BodyGround::automatic && config.root == RootControl::free_servo);
  sim::set_root_mode(*c.b_, config.root == RootControl::kinematic ? sim::RootMode::kinematic : sim::RootMode::free);
  im.in_a = sim::make_inputs(model);
  im.in_b = sim::make_inputs(model);
  // A is the ideal tracker: no torque limit of its own. The human limits are
  // B's (its drives), and the feedforward A hands B is bounded by them.
  im.in_a.torque_limit_nm.fill(0.0);
  write_stiff_gains(model, c.mapper_, config.stiff_hz, config.stiff_ungrouped_hz, config.stiff_damping_ratio, im.in_a);
  if (config.root == RootControl::free_servo) {
    const double w = 2.0 * M_PI * config.root_servo_hz;
    const double m = model.total_mass_kg();
    const double i = c.mapper_.inertia(3);  // the whole body about the root's first rotation axis
    im.in_b.root_servo = {true, w * w * m, 2.0 * w * m, w * w * i, 2.0 * w * i};
  }
  for (size_t b = 0; b < sim::kBoneCount; ++b) im.bone_geom[b] = model.first_geom(static_cast<int>(b));
  im.ref = rest_reference(model);
  im.followed = im.ref;
  im.window_ticks = std::clamp<std::size_t>(
      static_cast<std::size_t>(std::lround(config.jump_window_s / model.timestep_s)), 1, kMaxJumpWindowTicks);
  made.controller.emplace(std::move(c));
  made.controller->out_.qpos = model.qpos0;
  return made;
}

void AvatarController::set_stiffness_now(const std::array<double, kGroupCount>& s) { mapper_.set_applied(s); }

void AvatarController::resync(const ReferencePose& ref) {
  const sim::Model& m = *model_;
  for (sim::Data* d : {a_.get(), b_.get()}) {
    std::copy_n(ref.qpos.begin(), m.nq, d->qpos.begin());
    for (size_t k = 0; k < static_cast<size_t>(m.nv); ++k) d->qvel[k] = ref.has_velocity ? ref.qvel[k] : 0.0;
    d->drive_in_rows.fill(false);
    d->drive_impulse.fill(0.0);
    sim::forward_kinematics(m, *d);
  }
  impl_->prev_qpos = ref.qpos;
  impl_->has_prev = true;
  impl_->window_count = 0;
  impl_->remember(ref.qpos);
  if (impl_->id) impl_->id->reset();
}

namespace {

void set_targets(const sim::Model& m, const ReferencePose& r, sim::StepInputs& in) {
  std::copy_n(r.qpos.begin(), m.nq, in.target_qpos.begin());
  std::copy_n(r.qvel.begin(), m.nv, in.target_qvel.begin());
  in.root_pos = sim::Vec3(r.qpos[0], r.qpos[1], r.qpos[2]);
  in.root_quat = sim::Quat(r.qpos[3], r.qpos[4], r.qpos[5], r.qpos[6]);
  in.root_lin_vel = sim::Vec3(r.qvel[0], r.qvel[1], r.qvel[2]);
  in.root_ang_vel = sim::Vec3(r.qvel[3], r.qvel[4], r.qvel[5]);
}

// Each joint's feedforward bounded by its torque limit (the norm over its dofs).
bool bound_feedforward(const sim::Model& m, const sim::StepInputs& limits, std::span<double> tau) {
  bool clamped = false;
  for (int i = 1; i < m.nbody; ++i) {
    const sim::Body& b = m.bodies[static_cast<size_t>(i)];
    const double limit = limits.torque_limit_nm[static_cast<size_t>(i)];
    if (!(limit > 0.0) || b.dof_num == 0) continue;
    const auto d0 = static_cast<size_t>(b.dof_adr);
    double n2 = 0.0;
    for (size_t d = d0; d < d0 + static_cast<size_t>(b.dof_num); ++d) n2 += tau[d] * tau[d];
    const double n = std::sqrt(n2);
    if (n > limit) {
      for (size_t d = d0; d < d0 + static_cast<size_t>(b.dof_num); ++d) tau[d] *= limit / n;
      clamped = true;
    }
  }
  return clamped;
}

// A Data set to a reference pose (A in variants without a second simulation).
void mirror(const sim::Model& m, const ReferencePose& r, sim::Data& d) {
  std::copy_n(r.qpos.begin(), m.nq, d.qpos.begin());
  std::copy_n(r.qvel.begin(), m.nv, d.qvel.begin());
  sim::forward_kinematics(m, d);
  std::fill_n(d.tau_pd.begin(), m.nv, 0.0);
  std::fill_n(d.tau_ff.begin(), m.nv, 0.0);
}

// Kinetic energy of the articulation alone: a heavy or fast gift in flight is not a blow-up of B.
double articulation_kinetic_j(const sim::Model& m, const sim::Data& d) {
  const sim::Energy e = sim::energy(m, d);
  return e.kinetic_j - e.objects_kinetic_j;
}

}  // namespace

const TickOutput& AvatarController::tick(const TickInput& in) {
  const sim::Model& m = *model_;
  Impl& im = *impl_;
  const double dt = m.timestep_s;
  const auto nv = static_cast<size_t>(m.nv);
  std::uint32_t flags = 0;
  ++stats_.ticks;

  // 1. The reference: checked, clamped into range, jumps resynced, velocities.
  bool fresh = detail::reference_usable(m, in.reference);
  if (fresh) {
    im.ref = in.reference;
    detail::normalize(m, im.ref);
    if (sim::clamp_to_limits(m, im.ref.qpos) > 0) {
      flags |= kReferenceClamped;
      ++stats_.reference_clamped;
    }
  } else {
    flags |= kReferenceInvalid;  // hold the last valid pose, at rest
    ++stats_.reference_invalid;
    im.ref.has_velocity = false;
  }
  if (!im.has_prev) {
    im.ref.has_velocity = im.ref.has_velocity && fresh;
    resync(im.ref);
  } else {
    const detail::StepSize step = detail::step_size(m, im.oldest(), im.ref.qpos);
    if (step.joint_rad > config_.jump_rad || step.root_m > config_.jump_m) {
      flags |= kReferenceJump;
      ++stats_.reference_jumps;
      im.ref.has_velocity = false;
      resync(im.ref);
    } else {
      im.remember(im.ref.qpos);
    }
  }
  if (!im.ref.has_velocity || !fresh) detail::difference(m, im.prev_qpos, im.ref.qpos, dt, im.ref.qvel);
  im.prev_qpos = im.ref.qpos;

  // 2. Stiffness -> B's gains.
  // Effective inertia at B's posture (its last step's joint-space inertia).
  if (stats_.ticks > 1) mapper_.set_inertia(b_->mass, m.nv);
  const StiffnessMapper::Update su = mapper_.update(in.stiffness, dt);
  if (su.rejected > 0) flags |= kStiffnessInvalid;
  if (su.clamped > 0) flags |= kStiffnessClamped;
  if (su.rate_limited) flags |= kStiffnessRateLimited;
  stats_.stiffness_invalid += static_cast<std::uint64_t>(su.rejected);
  stats_.stiffness_clamped += static_cast<std::uint64_t>(su.clamped);
  mapper_.write_gains(m, im.in_b);
  write_stiff_gains(m, mapper_, config_.stiff_hz, config_.stiff_ungrouped_hz, config_.stiff_damping_ratio, im.in_a);

  // 3. Simulation A (or the reference mirrored), and the feedforward.
  std::array<double, sim::kMaxDofs> tau_ff{};
  switch (config_.feedforward) {
    case Feedforward::simulation: {
      im.followed = im.ref;
      set_targets(m, im.followed, im.in_a);
      if (sim::step(m, *a_, im.in_a) == sim::StepStatus::diverged) {
        flags |= kResetA;
        ++stats_.resets_a;
        mirror(m, im.followed, *a_);
      }
      for (size_t d = 6; d < nv; ++d) tau_ff[d] = a_->tau_pd[d] + a_->tau_ff[d];
      break;
    }
    case Feedforward::inverse_dynamics: {
      if (!im.id->push(m, im.ref, im.followed, im.tau_id)) flags |= kWarmingUp;
      for (size_t d = 6; d < nv; ++d) tau_ff[d] = im.tau_id[d];
      mirror(m, im.followed, *a_);
      break;
    }
    case Feedforward::none:
      im.followed = im.ref;
      mirror(m, im.followed, *a_);
      break;
  }
  if (bound_feedforward(m, im.in_b, tau_ff)) {
    flags |= kFeedforwardClamped;
    ++stats_.feedforward_clamped;
  }

  // 4. Simulation B.
  set_targets(m, im.followed, im.in_b);
  std::copy_n(tau_ff.begin(), nv, im.in_b.tau_ff.begin());
  const sim::StepStatus sb = sim::step(m, *b_, im.in_b);
  if (b_->diag.contact_overflow != im.contact_overflow_seen) flags |= kContactOverflow;
  im.contact_overflow_seen = b_->diag.contact_overflow;
  const double ke_a = articulation_kinetic_j(m, *a_);
  const double ke_b = articulation_kinetic_j(m, *b_);
  if (sb == sim::StepStatus::diverged ||
      !(ke_b <= config_.blowup_energy_factor * ke_a + config_.blowup_energy_margin_j)) {
    flags |= kResetB;
    ++stats_.resets_b;
    std::copy_n(a_->qpos.begin(), m.nq, b_->qpos.begin());
    std::copy_n(a_->qvel.begin(), m.nv, b_->qvel.begin());
    b_->drive_in_rows.fill(false);
    b_->drive_impulse.fill(0.0);
    // A diverged step was undone, B's clock included: the reset stands for this
    // tick, so the clock moves on (else gifts' lifetimes and time_s stall).
    if (sb == sim::StepStatus::diverged) b_->time_s += dt;
    for (sim::Object& o : b_->objects) {  // gifts flung in the blow-up are stopped too
      if (!o.active || o.lin_vel.norm() < 100.0) continue;
      o.lin_vel.setZero();
      o.ang_vel.setZero();
    }
    sim::forward_kinematics(m, *b_);
  }

  // 5. Gifts that expired or fell off the world.
  for (GiftSlot& g : im.gifts) {
    if (!g.live) continue;
    const sim::Object* o = sim::find_object(*b_, {g.id.slot, g.id.generation});
    const bool gone =
        o == nullptr || (g.expires_s > 0.0 && b_->time_s >= g.expires_s) || o->pos.z() < config_.gift_floor_m;
    if (gone) {
      sim::remove_object(*b_, {g.id.slot, g.id.generation});
      g.live = false;
      flags |= kGiftExpired;
      ++stats_.gifts_expired;
    }
  }

  // 6. Outputs.
  TickOutput& o = out_;
  o.time_s = b_->time_s;
  std::copy_n(b_->qpos.begin(), m.nq, o.qpos.begin());
  std::copy_n(b_->qvel.begin(), m.nv, o.qvel.begin());
  for (size_t i = 0; i < std::min(static_cast<size_t>(m.nbody), sim::kBoneCount); ++i) o.bones[i] = b_->xbody[i];
  o.reference_qpos = im.followed.qpos;
  detail::joint_angles_between(m, b_->qpos, im.followed.qpos, o.deviation_rad);
  for (size_t d = 0; d < nv; ++d) {
    o.tau_a[d] = a_->tau_pd[d] + a_->tau_ff[d];
    o.tau_b[d] = b_->tau_pd[d] + b_->tau_ff[d];
    o.tau_ff[d] = tau_ff[d];
  }
  o.stiffness = mapper_.applied();
  o.root_force = b_->root_wrench_force;
  o.root_torque = b_->root_wrench_torque;
  o.nevents = 0;
  for (int c = 0; c < b_->ncon; ++c) {
    const sim::Contact& ct = b_->contacts[static_cast<size_t>(c)];
    const bool a_body = ct.a.kind == sim::ContactSide::Kind::body;
    const sim::ContactSide& body = a_body ? ct.a : ct.b;
    const sim::ContactSide& obj = a_body ? ct.b : ct.a;
    if (body.kind != sim::ContactSide::Kind::body || obj.kind != sim::ContactSide::Kind::object) continue;
    if (body.index < 0 || body.index >= static_cast<int>(sim::kBoneCount)) continue;
    const auto bone = static_cast<sim::Bone>(body.index);
    const GiftId id{obj.index, b_->objects[static_cast<size_t>(obj.index)].generation};
    ContactEvent* e = nullptr;
    for (int k = 0; k < o.nevents; ++k) {
      ContactEvent& x = o.events[static_cast<size_t>(k)];
      if (x.bone == bone && x.gift == id) e = &x;
    }
    if (e == nullptr) {
      if (o.nevents >= static_cast<int>(kMaxContactEvents)) {
        flags |= kEventOverflow;
        ++stats_.event_overflow;
        continue;
      }
      e = &o.events[static_cast<size_t>(o.nevents++)];
      *e = ContactEvent{bone, id, 0.0, ct.pos, a_body ? ct.normal : sim::Vec3(-ct.normal)};
    }
    e->impulse_ns += ct.impulse.x();
  }
  o.flags = flags;
  return o;
}

int AvatarController::gift_count() const {
  int n = 0;
  for (const GiftSlot& g : impl_->gifts) n += g.live ? 1 : 0;
  return n;
}

namespace {

bool positive_below(double x, double max) { return std::isfinite(x) && x > 0.0 && x <= max; }

// Height of a shape's top above its centre, world z.
double top_above_centre(const sim::Shape& s, const sim::Pose& p) {
  switch (s.type) {
    case sim::ShapeType::sphere: return s.radius_m;
    case sim::ShapeType::capsule: return s.radius_m + s.half_length_m * std::abs(p.rot(2, 2));
    case sim::ShapeType::box:
      return std::abs(p.rot(2, 0)) * s.half_extents_m.x() + std::abs(p.rot(2, 1)) * s.half_extents_m.y() +
             std::abs(p.rot(2, 2)) * s.half_extents_m.z();
    case sim::ShapeType::plane: return 0.0;
  }
  return 0.0;
}

GiftError to_gift_error(sim::ObjectError e) {
  return e == sim::ObjectError::full ? GiftError::full : GiftError::bad_params;
}

}  // namespace

SpawnResult AvatarController::throw_ball(const ThrowBall& s) {
  const sim::Model& m = *model_;
  SpawnResult r;
  const auto bone = sim::index(s.target);
  if (bone >= sim::kBoneCount || impl_->bone_geom[bone] < 0) {
    r.error = GiftError::bad_target;
  } else if (!positive_below(s.mass_kg, 1000.0) || !positive_below(s.radius_m, 2.0) ||
             !positive_below(s.speed_mps, 100.0) || !positive_below(s.distance_m, 50.0) ||
             !std::isfinite(s.lifetime_s) || s.lifetime_s < 0.0 || !s.direction.allFinite() ||
             !(s.restitution >= 0.0 && s.restitution <= 1.0) || !(s.friction >= 0.0 && s.friction <= 10.0)) {
    r.error = GiftError::bad_params;
  }
  if (r.error != GiftError::none) {
    ++stats_.gifts_refused;
    return r;
  }
  const sim::Vec3 target = b_->xgeom[static_cast<size_t>(impl_->bone_geom[bone])].pos;
  sim::Vec3 dir = s.direction;
  if (dir.norm() < 1e-9) dir = -b_->xbody[0].rot.col(0);  // from straight ahead
  dir.stableNormalize();  // a huge vector is a direction too (normalize() would overflow to zero)
  const double t = s.distance_m / s.speed_mps;
  const sim::Vec3 g = m.features.gravity ? m.gravity : sim::Vec3::Zero();
  sim::ObjectSpec o;
  o.shape = sim::Shape::sphere(s.radius_m);
  o.mass_kg = s.mass_kg;
  o.material = {s.friction, s.restitution};
  o.pos = target - dir * s.distance_m;
  o.lin_vel = dir * s.speed_mps - 0.5 * g * t;  // lands on the target despite gravity
  return spawn(o, s.lifetime_s);
}

SpawnResult AvatarController::drop_cube(const DropCube& s) {
  SpawnResult r;
  const auto bone = sim::index(s.target);
  if (bone >= sim::kBoneCount || impl_->bone_geom[bone] < 0) {
    r.error = GiftError::bad_target;
  } else if (!positive_below(s.mass_kg, 1000.0) || !positive_below(s.edge_m, 2.0) || !std::isfinite(s.height_m) ||
             s.height_m < 0.0 || s.height_m > 50.0 || !std::isfinite(s.lifetime_s) || s.lifetime_s < 0.0 ||
             !(s.friction >= 0.0 && s.friction <= 10.0)) {
    r.error = GiftError::bad_params;
  }
  if (r.error != GiftError::none) {
    ++stats_.gifts_refused;
    return r;
  }
  const auto g = static_cast<size_t>(impl_->bone_geom[bone]);
  const sim::Pose& p = b_->xgeom[g];
  sim::ObjectSpec o;
  o.shape = sim::Shape::box(sim::Vec3::Constant(0.5 * s.edge_m));
  o.mass_kg = s.mass_kg;
  o.material.friction = s.friction;
  o.pos = p.pos + sim::Vec3(0, 0, top_above_centre(model_->geoms[g].shape, p) + s.height_m + 0.5 * s.edge_m);
  return spawn(o, s.lifetime_s);
}

SpawnResult AvatarController::spawn(const sim::ObjectSpec& o, double lifetime_s) {
  SpawnResult r;
  const sim::AddObjectResult added = sim::add_object(*b_, o);
  if (added.error != sim::ObjectError::none) {
    r.error = to_gift_error(added.error);
    ++stats_.gifts_refused;
    return r;
  }
  r.id = {added.handle.slot, added.handle.generation};
  impl_->gifts[static_cast<size_t>(r.id.slot)] = {true, r.id, lifetime_s > 0.0 ? b_->time_s + lifetime_s : 0.0};
  ++stats_.gifts_spawned;
  return r;
}

GiftError AvatarController::remove(GiftId id) {
  if (id.slot < 0 || id.slot >= static_cast<int>(sim::kMaxObjects)) return GiftError::not_found;
  GiftSlot& g = impl_->gifts[static_cast<size_t>(id.slot)];
  if (!g.live || !(g.id == id)) return GiftError::not_found;
  sim::remove_object(*b_, {id.slot, id.generation});
  g.live = false;
  return GiftError::none;
}

void AvatarController::clear_gifts() {
  for (GiftSlot& g : impl_->gifts) {
    if (g.live) sim::remove_object(*b_, {g.id.slot, g.id.generation});
    g.live = false;
  }
}

}  // namespace tonus::avatar
