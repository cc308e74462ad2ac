#include "tonus/host/reference/body_retarget.hpp"

#include <algorithm>
#include <cmath>

#include "rig.hpp"
#include "rotations.hpp"
#include "smoothstep.hpp"
#include "stream_checks.hpp"
#include "tonus/sim/joint_limits.hpp"

namespace tonus::reference {
namespace {

using sim::Bone;
using sim::Quat;
using sim::Vec3;

constexpr std::size_t kN = sim::kBoneCount;
constexpr double kDeg = M_PI / 180.0;
// A limb bent less than this against the source's own hinge axis is
// overstretched, not bent the other way (which would turn the limb over).
constexpr double kOverstretch_rad = 20.0 * kDeg;
// Below kStraight0 a limb's plane is the source's own twist; above
// kStraight1 the plane of the upper and lower segments; blended between.
constexpr double kStraight0_rad = 2.0 * kDeg;
constexpr double kStraight1_rad = 10.0 * kDeg;

struct Limb {
  Bone upper, lower, end;
};
constexpr Limb kLimbs[4] = {{Bone::LeftUpperArm, Bone::LeftLowerArm, Bone::LeftHand},
                            {Bone::RightUpperArm, Bone::RightLowerArm, Bone::RightHand},
                            {Bone::LeftUpperLeg, Bone::LeftLowerLeg, Bone::LeftFoot},
                            {Bone::RightUpperLeg, Bone::RightLowerLeg, Bone::RightFoot}};
constexpr Bone kRequired[] = {Bone::Hips,          Bone::LeftUpperLeg,  Bone::LeftLowerLeg,  Bone::LeftFoot,
                              Bone::RightUpperLeg, Bone::RightLowerLeg, Bone::RightFoot,     Bone::LeftUpperArm,
                              Bone::LeftLowerArm,  Bone::LeftHand,      Bone::RightUpperArm, Bone::RightLowerArm,
                              Bone::RightHand};

constexpr std::size_t idx(Bone b) { return sim::index(b); }
constexpr std::uint32_t bit(std::size_t i) { return std::uint32_t{1} << i; }
using detail::parent_of;
using detail::usable;

bool is_foot(Bone b) { return b == Bone::LeftFoot || b == Bone::RightFoot; }
bool is_shoulder(Bone b) { return b == Bone::LeftShoulder || b == Bone::RightShoulder; }
bool is_toes(Bone b) { return b == Bone::LeftToes || b == Bone::RightToes; }
bool is_limb_upper(std::size_t i) {
  return std::any_of(std::begin(kLimbs), std::end(kLimbs), [&](const Limb& l) { return idx(l.upper) == i; });
}
bool is_limb_lower(std::size_t i) {
  return std::any_of(std::begin(kLimbs), std::end(kLimbs), [&](const Limb& l) { return idx(l.lower) == i; });
}

// The least turn taking a onto b, deterministic when they are opposite (about `fallback_axis`).
Quat least_turn(const Vec3& a, const Vec3& b, const Vec3& fallback_axis) {
  const Vec3 a1 = a.normalized(), b1 = b.normalized();
  if (a1.dot(b1) < -1.0 + 1e-9) {
    Vec3 axis = fallback_axis - fallback_axis.dot(a1) * a1;
    if (axis.norm() < 1e-6) axis = a1.unitOrthogonal();
    return Quat(Eigen::AngleAxisd(M_PI, axis.normalized()));
  }
  return sim::quat_from_two_vectors(a1, b1);
}

void write_quat(std::span<double> q, std::size_t a, const Quat& r) {
  q[a] = r.w();
  q[a + 1] = r.x();
  q[a + 2] = r.y();
  q[a + 3] = r.z();
}

}  // namespace

SourceSkeleton skeleton_of(const sim::Model& m) {
  SourceSkeleton s;
  const auto n = std::min<std::size_t>(kN, static_cast<std::size_t>(std::max(m.nbody, 0)));
  for (std::size_t i = 0; i < n; ++i) {
    const sim::Body& b = m.bodies[i];
    s.present[i] = true;
    if (i == 0) {
      const auto a = static_cast<std::size_t>(b.qpos_adr);
      s.offset[0] = Vec3(m.qpos0[a], m.qpos0[a + 1], m.qpos0[a + 2]);
      s.rest_rotation[0] = Quat(m.qpos0[a + 3], m.qpos0[a + 4], m.qpos0[a + 5], m.qpos0[a + 6]);
    } else {
      s.offset[i] = b.pos_in_parent;
      s.rest_rotation[i] = b.quat_in_parent;
    }
  }
  return s;
}

SourceSkeleton a_pose_variant(const SourceSkeleton& t, double arms_down_rad, double arm_scale, double leg_scale) {
  SourceSkeleton s = t;
  s.rest_rotation[idx(Bone::LeftUpperArm)] =
      Quat(Eigen::AngleAxisd(-arms_down_rad, Vec3::UnitX())) * t.rest_rotation[idx(Bone::LeftUpperArm)];
  s.rest_rotation[idx(Bone::RightUpperArm)] =
      Quat(Eigen::AngleAxisd(arms_down_rad, Vec3::UnitX())) * t.rest_rotation[idx(Bone::RightUpperArm)];
  for (const Bone b : {Bone::LeftLowerArm, Bone::LeftHand, Bone::RightLowerArm, Bone::RightHand}) {
    s.offset[idx(b)] *= arm_scale;
  }
  for (const Bone b : {Bone::LeftLowerLeg, Bone::LeftFoot, Bone::RightLowerLeg, Bone::RightFoot}) {
    s.offset[idx(b)] *= leg_scale;
  }
  const double leg_drop = -(t.offset[idx(Bone::LeftLowerLeg)].z() + t.offset[idx(Bone::LeftFoot)].z());
  s.offset[0].z() += (leg_scale - 1.0) * leg_drop;
  return s;
}

BodyRetargetBuild BodyRetarget::create(const sim::Model& humanoid, const SourceSkeleton& source,
                                       const BodyRetargetOptions& options) {
  BodyRetargetBuild out;
  detail::Rig rig;
  out.error = detail::make_rig(humanoid, rig);
  if (!out.error.empty()) return out;
  if (!(options.unit_tolerance >= 0.0 && options.unit_tolerance < 0.5) || !(options.max_root_distance_m > 0.0)) {
    out.error = "options: unit_tolerance must be in [0, 0.5) and max_root_distance_m positive";
    return out;
  }
  for (const Bone b : kRequired) {
    if (!source.present[idx(b)]) {
      out.error = "the source skeleton lacks " + std::string(sim::name(b));
      return out;
    }
  }
  if (!source.present[idx(Bone::Neck)] && !source.present[idx(Bone::Head)]) {
    out.error = "the source skeleton has neither a neck nor a head";
    return out;
  }
  BodyRetarget r;
  r.model_ = &humanoid;
  r.options_ = options;
  r.source_ = source;
  SourceSkeleton& s = r.source_;
  for (std::size_t i = 0; i < kN; ++i) {
    if (!s.present[i]) continue;
    const std::string name(sim::kBones[i].name);
    if (!sim::all_finite(s.offset[i]) || s.offset[i].norm() > 100.0) {
      out.error = "the source's rest offset of " + name + " is not finite or beyond 100 m";
      return out;
    }
    if (!usable(s.rest_rotation[i], options.unit_tolerance)) {
      out.error = "the source's rest rotation of " + name + " is not a unit quaternion";
      return out;
    }
    s.rest_rotation[i].normalize();
  }

  // The source's rest: parents, world rotations and joint positions.
  std::array<Vec3, kN> src_pos{};
  r.source_parent_.fill(-1);
  r.source_rest_world_.fill(Quat::Identity());
  r.source_rest_world_[0] = s.rest_rotation[0];
  src_pos[0] = s.offset[0];
  for (std::size_t i = 1; i < kN; ++i) {
    if (!s.present[i]) continue;
    const std::size_t p = detail::present_parent(s.present, i);  // Hips is present
    r.source_parent_[i] = static_cast<int>(p);
    r.source_rest_world_[i] = (r.source_rest_world_[p] * s.rest_rotation[i]).normalized();
    src_pos[i] = src_pos[p] + r.source_rest_world_[p] * s.offset[i];
  }
  // The humanoid's rest joint positions (world).
  std::array<Vec3, kN> hum_pos{};
  hum_pos[0] = s.offset[0];  // any: only differences are used
  for (std::size_t i = 1; i < kN; ++i) {
    const std::size_t p = parent_of(i);
    hum_pos[i] = hum_pos[p] + rig.rest_world[p] * rig.body(sim::kBones[i].bone).pos_in_parent;
  }
  for (std::size_t i = 0; i < kN; ++i) {
    r.dir_[i] = rig.dir[i];
    r.length_[i] = rig.length[i];
    r.rest_world_[i] = rig.rest_world[i];
  }
  r.hip_mid_ = rig.hip_mid;

  // Alignment. Pelvis: the hip line exactly, the way to the spine as near as that allows.
  const auto first_present = [&](std::initializer_list<Bone> bones) -> std::optional<std::size_t> {
    for (const Bone b : bones) {
      if (s.present[idx(b)]) return idx(b);
    }
    return std::nullopt;
  };
  const std::size_t lul = idx(Bone::LeftUpperLeg), rul = idx(Bone::RightUpperLeg);
  const std::size_t trunk = *first_present({Bone::Spine, Bone::Chest, Bone::Neck, Bone::Head});
  const Vec3 src_hip_line = src_pos[lul] - src_pos[rul];
  if (src_hip_line.norm() < 1e-4) {
    out.error = "the source's hip joints coincide at rest";
    return out;
  }
  Quat hips = Quat::Identity();
  if (!detail::frame_match(hum_pos[lul] - hum_pos[rul], hum_pos[trunk] - hum_pos[0], src_hip_line,
                           src_pos[trunk] - src_pos[0], hips)) {
    hips = least_turn(hum_pos[lul] - hum_pos[rul], src_hip_line, Vec3::UnitZ());
  }
  r.align_[0] = hips;
  for (std::size_t i = 1; i < kN; ++i) {
    const Bone b = sim::kBones[i].bone;
    const Quat& inherited = r.align_[parent_of(i)];
    r.align_[i] = inherited;
    // Absent bones, shoulders (skeletons disagree where the clavicle starts:
    // CMU's at the spine) and toes (flat with the foot) keep their parent's.
    if (!s.present[i] || is_shoulder(b) || is_toes(b)) continue;
    // The next present joint down the chain, the segment's far end in both skeletons.
    std::optional<Bone> c = detail::chain_child(b);
    while (c && !s.present[idx(*c)]) c = detail::chain_child(*c);
    if (!c) continue;  // an end bone (head, hands): as its parent
    const Vec3 h = hum_pos[idx(*c)] - hum_pos[i], d = src_pos[idx(*c)] - src_pos[i];
    if (h.norm() < 1e-6 || d.norm() < 1e-6) continue;
    if (is_foot(b)) {
      // Neutral with the shank (its pitch is the skeleton's design, not a
      // pose), turned about the shank to the source foot's heading.
      const Vec3 shank = inherited * (hum_pos[i] - hum_pos[idx(*sim::kBones[i].parent)]);
      if (shank.norm() > 1e-6) {
        const Vec3 axis = shank.normalized();
        r.align_[i] = Quat(Eigen::AngleAxisd(detail::angle_about(axis, inherited * h, d), axis)) * inherited;
      }
      continue;
    }
    r.align_[i] = least_turn(h, d, inherited * Vec3::UnitX());
  }

  // Scale and height: leg lengths (hip to ankle), and the rest pose's feet on z = 0.
  const auto leg = [&](const std::array<Vec3, kN>& pos, Bone thigh) {
    const std::size_t t0 = idx(thigh);
    return (pos[t0 + 1] - pos[t0]).norm() + (pos[t0 + 2] - pos[t0 + 1]).norm();
  };
  const double src_leg = 0.5 * (leg(src_pos, Bone::LeftUpperLeg) + leg(src_pos, Bone::RightUpperLeg));
  const double hum_leg = 0.5 * (leg(hum_pos, Bone::LeftUpperLeg) + leg(hum_pos, Bone::RightUpperLeg));
  if (!(src_leg > 0.05)) {
    out.error = "the source's legs are shorter than 5 cm";
    return out;
  }
  r.scale_ = hum_leg / src_leg;
  // Both mid-hips in their Hips frames: the source's from its hip offsets.
  r.source_hip_mid_ = 0.5 * (s.offset[lul] + s.offset[rul]);
  const sim::Body& root = rig.body(Bone::Hips);
  const auto a = static_cast<std::size_t>(root.qpos_adr);
  const Vec3 hum_root(humanoid.qpos0[a], humanoid.qpos0[a + 1], humanoid.qpos0[a + 2]);
  const double hum_mid_z = (hum_root + rig.rest_world[0] * r.hip_mid_).z();
  const double src_mid_z = (s.offset[0] + r.source_rest_world_[0] * r.source_hip_mid_).z();
  r.z_offset_ = hum_mid_z - r.scale_ * src_mid_z;
  out.retarget = r;
  return out;
}

BodyStatus BodyRetarget::solve(const BodySample& in, BodyRetargetState& st, std::span<double> qpos_out) const {
  BodyStatus status;
  const sim::Model& m = *model_;
  const auto nq = static_cast<std::size_t>(m.nq);
  if (qpos_out.size() < nq) return status;
  const SourceSkeleton& s = source_;
  if (!st.started) {
    st.last_local = s.rest_rotation;
    st.last_root_position = s.offset[0];
    st.last_root_rotation = s.rest_rotation[0];
    st.previous = m.qpos0;
    st.started = true;
  }

  // Inputs: the last valid value where one is missing or unusable.
  std::array<Quat, kN> local{};
  for (std::size_t i = 1; i < kN; ++i) {
    if (!s.present[i]) continue;
    if (!in.present[i]) {
      status.missing_bones |= bit(i);
      local[i] = options_.missing_keeps_last ? st.last_local[i] : s.rest_rotation[i];
      continue;
    }
    if (usable(in.local[i], options_.unit_tolerance)) {
      st.last_local[i] = in.local[i].normalized();
    } else {
      status.invalid_bones |= bit(i);
    }
    local[i] = st.last_local[i];
  }
  Vec3 root_pos = st.last_root_position;
  Quat root_rot = st.last_root_rotation;
  if (!in.root_present) {
    status.root_missing = true;
    if (!options_.missing_keeps_last) {
      root_pos = s.offset[0];
      root_rot = s.rest_rotation[0];
    }
  } else {
    if (sim::all_finite(in.root_position) && in.root_position.norm() <= options_.max_root_distance_m) {
      root_pos = st.last_root_position = in.root_position;
    } else {
      status.root_position_invalid = true;
    }
    if (usable(in.root_rotation, options_.unit_tolerance)) {
      root_rot = st.last_root_rotation = in.root_rotation.normalized();
    } else {
      status.root_rotation_invalid = true;
    }
  }

  // Each bone's turn from its rest (D), then the humanoid's target (D * A).
  std::array<Quat, kN> src_world{}, turn{}, target{};
  src_world[0] = root_rot;
  turn[0] = (root_rot * source_rest_world_[0].conjugate()).normalized();
  for (std::size_t i = 1; i < kN; ++i) {
    if (s.present[i]) {
      src_world[i] = (src_world[static_cast<std::size_t>(source_parent_[i])] * local[i]).normalized();
      turn[i] = (src_world[i] * source_rest_world_[i].conjugate()).normalized();
    } else {
      turn[i] = turn[parent_of(i)];  // rigid with its parent
    }
  }
  for (std::size_t i = 0; i < kN; ++i) target[i] = (turn[i] * align_[i] * rest_world_[i]).normalized();

  // The humanoid, root to leaves.
  std::array<double, sim::kMaxQpos> q = m.qpos0;
  const std::span<double> qs(q.data(), q.size());
  std::array<Quat, kN> world{};
  const auto body = [&](std::size_t i) -> const sim::Body& { return m.bodies[i]; };
  const auto carried = [&](std::size_t i) { return Quat(world[parent_of(i)] * body(i).quat_in_parent); };
  const auto note_clamp = [&](std::size_t i, bool moved) {
    if (!moved) return;
    ++status.clamped;
    status.clamped_bones |= bit(i);
  };
  const auto set_ball = [&](std::size_t i, const Quat& want) {
    const Quat base = carried(i);
    Quat j = (base.conjugate() * want).normalized();
    note_clamp(i, sim::clamp_ball(body(i).limit, j));
    world[i] = (base * j).normalized();
    write_quat(qs, static_cast<std::size_t>(body(i).qpos_adr), j);
  };
  const auto set_hinge = [&](std::size_t i, double angle) {
    note_clamp(i, sim::clamp_hinge(body(i).limit, angle));
    world[i] = (carried(i) * Quat(Eigen::AngleAxisd(angle, body(i).hinge_axis))).normalized();
    q[static_cast<std::size_t>(body(i).qpos_adr)] = angle;
  };
  // The hinge angle of i that points its segment closest to d, under a parent turned to parent_world.
  const auto hinge_towards = [&](const Quat& parent_world, std::size_t i, const Vec3& d) {
    const Quat base = parent_world * body(i).quat_in_parent;
    return detail::angle_about(base * body(i).hinge_axis, base * dir_[i], d);
  };

  world[0] = target[0];
  const Vec3 src_mid = root_pos + root_rot * source_hip_mid_;
  const Vec3 root = scale_ * src_mid + Vec3(0.0, 0.0, z_offset_) - world[0] * hip_mid_;
  const auto r0 = static_cast<std::size_t>(body(0).qpos_adr);
  for (std::size_t k = 0; k < 3; ++k) q[r0 + k] = root[static_cast<Eigen::Index>(k)];
  write_quat(qs, r0 + 3, world[0]);

  // Elbow or knee: the upper bone twisted so the hinge axis is normal to the
  // limb's plane (near straight: the source's own twist), the hinge angle
  // clamped, and what it cannot do turned into the upper bone so the limb's
  // end still points where the source's does.
  const auto limb = [&](const Limb& l) {
    const std::size_t iu = idx(l.upper), il = idx(l.lower), ie = idx(l.end);
    const Quat& tu = target[iu];
    const Vec3 u = tu * dir_[iu], f = target[il] * dir_[il];
    const Vec3 hinge_in_upper = body(il).quat_in_parent * body(il).hinge_axis;
    Vec3 axis = tu * hinge_in_upper;  // the source's own twist
    const Vec3 ref_raw = axis - axis.dot(u) * u;
    const Vec3 n = u.cross(f);
    if (ref_raw.norm() > 1e-6 && n.norm() > 1e-9) {
      const Vec3 ref = ref_raw.normalized(), plane = n.normalized();
      const double bend = std::atan2(n.norm(), u.dot(f));
      const bool against = plane.dot(ref) < 0.0;
      if (!(against && bend < kOverstretch_rad)) {
        const double w =
            against ? 1.0 : detail::smoothstep((bend - kStraight0_rad) / (kStraight1_rad - kStraight0_rad));
        axis = w * plane + (1.0 - w) * ref;
      }
    }
    Quat upper = tu;
    detail::frame_match(dir_[iu], hinge_in_upper, u, axis, upper);
    double angle = hinge_towards(upper, il, f);
    sim::clamp_hinge(body(il).limit, angle);
    const Vec3 end_in_upper =
        body(il).pos_in_parent +
        body(il).quat_in_parent * (Quat(Eigen::AngleAxisd(angle, body(il).hinge_axis)) * body(ie).pos_in_parent);
    const Vec3 want = length_[iu] * u + length_[il] * f;
    const Vec3 now = upper * end_in_upper;
    if (now.norm() > detail::kTiny && want.norm() > detail::kTiny) {
      upper = (sim::quat_from_two_vectors(now, want) * upper).normalized();
    }
    set_ball(iu, upper);
    set_hinge(il, hinge_towards(world[iu], il, f));
  };

  for (std::size_t i = 1; i < kN; ++i) {
    if (is_limb_lower(i)) continue;  // with its upper bone
    if (is_limb_upper(i)) {
      for (const Limb& l : kLimbs) {
        if (idx(l.upper) == i) limb(l);
      }
    } else if (body(i).joint == sim::JointType::hinge) {
      set_hinge(i, hinge_towards(world[parent_of(i)], i, target[i] * dir_[i]));
    } else {
      set_ball(i, target[i]);
    }
  }

  // Continuity: each quaternion in the previous output's hemisphere; nothing non-finite out.
  bool ok = true;
  detail::keep_hemisphere(m, q, st.previous);
  for (std::size_t k = 0; k < nq; ++k) ok = ok && std::isfinite(q[k]);
  if (ok) {
    st.previous = q;
  } else {
    status.fallback = true;
  }
  std::copy_n(st.previous.begin(), nq, qpos_out.begin());
  status.written = true;
  return status;
}

}  // namespace tonus::reference
