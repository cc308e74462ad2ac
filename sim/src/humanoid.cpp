// The humanoid builder. Every proportion and fraction below is documented,
// with its source, in docs/humanoid.md.
#include "tonus/sim/humanoid.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

#include <Eigen/Eigenvalues>

namespace tonus::sim {
namespace {

using std::size_t;

constexpr size_t bi(Bone b) { return index(b); }

// Winter (2009), Fig. 4.1: segment lengths as fractions of stature, and the
// heights of the landmarks the default skeleton places its joints at.
constexpr double kHipHeight = 0.530;
constexpr double kKneeHeight = 0.285;
constexpr double kAnkleHeight = 0.039;
constexpr double kShoulderHeight = 0.818;
constexpr double kUpperArm = 0.186;
constexpr double kForearm = 0.146;
constexpr double kHandToFingertip = 0.108;
constexpr double kHipJointHalfWidth = 0.052;  // hip joint centres ~0.1 H apart (a rounded typical value)
constexpr double kShoulderHalfWidth = 0.129;  // Winter's shoulder width 0.259 H
constexpr double kFootLength = 0.152;
constexpr double kHeelBehindAnkle = 0.035;  // of the foot length, 23 % lies behind the ankle
constexpr double kToeJointAhead = 0.085;    // metatarsophalangeal joints, ~56 % of the foot length
constexpr double kToeJointHeight = 0.010;
constexpr double kHeadLength = 0.110;  // head joint (skull base) to vertex

// Share of a de Leva segment given to an extra bone of ours.
constexpr double kShoulderShareOfUpperTrunk = 0.10;  // each scapula/clavicle
constexpr double kNeckShareOfHead = 0.20;            // de Leva's head segment includes the neck
constexpr double kToesShareOfFoot = 0.20;

// Human joint torque capacity for a 70 kg adult, N*m (order of the isometric
// maxima in the literature, see docs/humanoid.md); scaled with body mass.
double torque_limit_70kg(Bone b) {
  switch (b) {
    case Bone::Spine:
    case Bone::Chest: return 200.0;
    case Bone::Neck: return 40.0;
    case Bone::Head: return 20.0;
    case Bone::LeftShoulder:
    case Bone::RightShoulder: return 60.0;
    case Bone::LeftUpperArm:
    case Bone::RightUpperArm: return 80.0;
    case Bone::LeftLowerArm:
    case Bone::RightLowerArm: return 70.0;
    case Bone::LeftHand:
    case Bone::RightHand: return 20.0;
    case Bone::LeftUpperLeg:
    case Bone::RightUpperLeg: return 250.0;
    case Bone::LeftLowerLeg:
    case Bone::RightLowerLeg: return 220.0;
    case Bone::LeftFoot:
    case Bone::RightFoot: return 150.0;
    case Bone::LeftToes:
    case Bone::RightToes: return 30.0;
    case Bone::Hips: return 0.0;
  }
  return 0.0;
}

struct Range {
  JointType type;
  double swing;   // ball: cone half angle
  double lo, hi;  // ball: twist; hinge: angle
};

// Ranges of motion (AAOS / Kapandji, rounded; docs/humanoid.md).
Range range_of(Bone b) {
  switch (b) {
    case Bone::Hips: return {JointType::free, 0, 0, 0};
    case Bone::Spine: return {JointType::ball, 0.50, -0.50, 0.50};
    case Bone::Chest: return {JointType::ball, 0.40, -0.40, 0.40};
    case Bone::Neck: return {JointType::ball, 0.70, -0.90, 0.90};
    case Bone::Head: return {JointType::ball, 0.50, -0.60, 0.60};
    case Bone::LeftShoulder:
    case Bone::RightShoulder: return {JointType::ball, 0.35, -0.30, 0.30};
    case Bone::LeftUpperArm:
    case Bone::RightUpperArm: return {JointType::ball, 1.75, -1.50, 1.50};
    case Bone::LeftLowerArm:
    case Bone::RightLowerArm: return {JointType::hinge, 0, -0.05, 2.60};
    case Bone::LeftHand:
    case Bone::RightHand: return {JointType::ball, 1.20, -1.30, 1.30};  // twist carries pronation
    case Bone::LeftUpperLeg:
    case Bone::RightUpperLeg: return {JointType::ball, 1.60, -0.70, 0.70};
    case Bone::LeftLowerLeg:
    case Bone::RightLowerLeg: return {JointType::hinge, 0, -0.05, 2.40};
    case Bone::LeftFoot:
    case Bone::RightFoot: return {JointType::ball, 0.70, -0.40, 0.40};
    case Bone::LeftToes:
    case Bone::RightToes: return {JointType::hinge, 0, -0.90, 0.50};
  }
  return {JointType::fixed, 0, 0, 0};
}

// Hinge axes in the rest frame (flexion positive).
Vec3 hinge_axis(Bone b) {
  switch (b) {
    case Bone::LeftLowerArm: return -Vec3::UnitZ();  // forearm (+Y) swings forward (+X)
    case Bone::RightLowerArm: return Vec3::UnitZ();  // forearm (-Y) swings forward (+X)
    case Bone::LeftLowerLeg:                         // shank (-Z) swings back (-X)
    case Bone::RightLowerLeg:
    case Bone::LeftToes:  // positive curls the toes down
    case Bone::RightToes: return Vec3::UnitY();
    default: return Vec3::UnitX();
  }
}

// Principal inertia from radii of gyration (fractions of `len`) about the
// longitudinal axis `l` and the antero-posterior / medio-lateral axes.
Mat3 segment_inertia(double mass, double len, const Vec3& l, double rg_sag, double rg_trans, double rg_long) {
  Vec3 f = Vec3::UnitX() - Vec3::UnitX().dot(l) * l;                 // antero-posterior, orthogonal to the bone
  if (f.norm() < 0.3) f = Vec3::UnitZ() - Vec3::UnitZ().dot(l) * l;  // a foot: the bone is the AP axis
  f.normalize();
  const Vec3 s = l.cross(f);
  const auto moment = [&](double rg) { return mass * (rg * len) * (rg * len); };
  return moment(rg_sag) * f * f.transpose() + moment(rg_trans) * s * s.transpose() +
         moment(rg_long) * l * l.transpose();
}

Mat3 rod_inertia(double mass, double radius, double len, const Vec3& l) {
  const Mat3 local = cylinder_inertia(mass, radius, 0.5 * len);  // along z
  const Mat3 r = sim::quat_from_two_vectors(Vec3::UnitZ(), l).toRotationMatrix();
  return r * local * r.transpose();
}

Pose along(const Vec3& from, const Vec3& to) {
  Pose p;
  p.pos = 0.5 * (from + to);
  const Vec3 d = to - from;
  p.rot = sim::quat_from_two_vectors(Vec3::UnitZ(), d.norm() > 1e-9 ? Vec3(d.normalized()) : Vec3::UnitZ())
              .toRotationMatrix();
  return p;
}

// A capsule from `from` to `to` (body frame) of radius r, shortened so its caps end at the points.
GeomSpec capsule_between(int body, const Vec3& from, const Vec3& to, double r, const Material& mat) {
  GeomSpec g;
  g.body = body;
  const double half = std::max(0.5 * (to - from).norm() - r, 0.25 * r);
  g.shape = Shape::capsule(r, half);
  g.local = along(from, to);
  g.material = mat;
  return g;
}

GeomSpec box_at(int body, const Vec3& centre, const Vec3& half, const Material& mat) {
  GeomSpec g;
  g.body = body;
  g.shape = Shape::box(half);
  g.local.pos = centre;
  g.material = mat;
  return g;
}

Vec3 side(Bone b) { return info(b).side == Side::right ? Vec3(1, -1, 1) : Vec3(1, 1, 1); }

// Default gains: each joint a critically damped oscillator of the given
// natural frequency for the inertia of everything it carries (its subtree,
// about the joint, at rest): kp = w^2 I, kd = 2 zeta sqrt(kp I). Ball joints
// use the mean principal moment, hinges the moment about their axis.
void set_default_gains(std::array<BodySpec, kBoneCount>& bodies, double freq_hz, double zeta) {
  std::array<Vec3, kBoneCount> joint_pos{};
  for (size_t i = 0; i < kBoneCount; ++i) {
    const int p = bodies[i].parent;
    joint_pos[i] = (p >= 0 ? joint_pos[static_cast<size_t>(p)] : Vec3::Zero()) + bodies[i].pos_in_parent;
  }
  const double w = 2.0 * M_PI * freq_hz;
  for (size_t j = 1; j < kBoneCount; ++j) {
    Mat3 inertia = Mat3::Zero();
    for (size_t k = j; k < kBoneCount; ++k) {
      // k is in j's subtree when j is among its ancestors (parents come first).
      size_t a = k;
      while (a != j && bodies[a].parent > static_cast<int>(j)) a = static_cast<size_t>(bodies[a].parent);
      if (a != j && bodies[a].parent != static_cast<int>(j)) continue;
      const Vec3 r = joint_pos[k] + bodies[k].com - joint_pos[j];
      inertia += bodies[k].inertia + bodies[k].mass_kg * (r.squaredNorm() * Mat3::Identity() - r * r.transpose());
    }
    const double moment = bodies[j].joint == JointType::hinge ? bodies[j].hinge_axis.dot(inertia * bodies[j].hinge_axis)
                                                              : inertia.trace() / 3.0;
    bodies[j].drive.kp = w * w * moment;
    bodies[j].drive.kd = 2.0 * zeta * std::sqrt(bodies[j].drive.kp * moment);
  }
}

}  // namespace

std::array<Vec3, kBoneCount> default_skeleton(double h) {
  std::array<Vec3, kBoneCount> o{};
  o[bi(Bone::Hips)] = Vec3(0, 0, kHipHeight * h);
  o[bi(Bone::Spine)] = Vec3(0, 0, 0.100 * h);
  o[bi(Bone::Chest)] = Vec3(0, 0, 0.110 * h);
  o[bi(Bone::Neck)] = Vec3(0, 0, 0.100 * h);  // C7 at 0.84 H
  o[bi(Bone::Head)] = Vec3(0, 0, 0.050 * h);
  for (const Bone s : {Bone::LeftShoulder, Bone::RightShoulder}) {
    const Vec3 m = side(s);
    const size_t k = bi(s);
    o[k] = Vec3(0, 0.020 * h, kShoulderHeight * h - 0.740 * h).cwiseProduct(m);
    o[k + 1] = Vec3(0, (kShoulderHalfWidth - 0.020) * h, 0).cwiseProduct(m);  // UpperArm: shoulder joint
    o[k + 2] = Vec3(0, kUpperArm * h, 0).cwiseProduct(m);                     // LowerArm: elbow
    o[k + 3] = Vec3(0, kForearm * h, 0).cwiseProduct(m);                      // Hand: wrist
  }
  for (const Bone s : {Bone::LeftUpperLeg, Bone::RightUpperLeg}) {
    const Vec3 m = side(s);
    const size_t k = bi(s);
    o[k] = Vec3(0, kHipJointHalfWidth * h, 0).cwiseProduct(m);
    o[k + 1] = Vec3(0, 0, -(kHipHeight - kKneeHeight) * h);
    o[k + 2] = Vec3(0, 0, -(kKneeHeight - kAnkleHeight) * h);
    o[k + 3] = Vec3(kToeJointAhead * h, 0, -(kAnkleHeight - kToeJointHeight) * h);
  }
  return o;
}

ModelBuilder humanoid_builder(const HumanoidSpec& spec, std::string& error) {
  ModelBuilder mb;
  error.clear();
  const double h = spec.height_m;
  const double mass = spec.mass_kg;
  if (!std::isfinite(h) || h < 0.5 || h > 3.0) {
    error = "humanoid: height_m must be in [0.5, 3] m";
    return mb;
  }
  if (!std::isfinite(mass) || mass < 5.0 || mass > 500.0) {
    error = "humanoid: mass_kg must be in [5, 500] kg";
    return mb;
  }
  if (!std::isfinite(spec.drive_frequency_hz) || spec.drive_frequency_hz <= 0.0 || spec.drive_frequency_hz > 1000.0) {
    error = "humanoid: drive_frequency_hz must be in (0, 1000]";
    return mb;
  }
  if (!std::isfinite(spec.drive_damping_ratio) || spec.drive_damping_ratio < 0.0 || spec.drive_damping_ratio > 100.0) {
    error = "humanoid: drive_damping_ratio must be in [0, 100]";
    return mb;
  }
  const auto off = spec.bone_offsets ? *spec.bone_offsets : default_skeleton(h);
  for (size_t i = 0; i < kBoneCount; ++i) {
    if (!all_finite(off[i])) {
      error = "humanoid: bone offset of " + std::string(kBones[i].name) + " is not finite";
      return mb;
    }
    if (i > 0 && off[i].norm() < 0.005 * h) {
      error = "humanoid: bone offset of " + std::string(kBones[i].name) + " is shorter than 0.5 % of the height";
      return mb;
    }
  }
  const auto seg = [&](Segment s) { return de_leva(s, spec.sex); };
  const auto child_offset = [&](Bone b) -> Vec3 {
    switch (b) {
      case Bone::Hips: return off[bi(Bone::Spine)];
      case Bone::Spine: return off[bi(Bone::Chest)];
      case Bone::Chest: return off[bi(Bone::Neck)];
      case Bone::Neck: return off[bi(Bone::Head)];
      case Bone::Head: return Vec3(0, 0, kHeadLength * h);
      case Bone::LeftHand:
      case Bone::RightHand: {
        const Vec3 dir = off[bi(b)].normalized();  // continue the forearm
        return dir * (kHandToFingertip * h);
      }
      case Bone::LeftToes:
      case Bone::RightToes: {
        Vec3 dir = off[bi(b)];
        dir.z() = 0.0;
        dir = dir.norm() > 1e-9 ? Vec3(dir.normalized()) : Vec3::UnitX();
        return dir * ((kFootLength - kHeelBehindAnkle - kToeJointAhead) * h);
      }
      default: return off[bi(b) + 1];  // the next bone in the chain
    }
  };

  // Masses (fractions of the body mass).
  std::array<double, kBoneCount> frac{};
  frac[bi(Bone::Hips)] = seg(Segment::lower_trunk).mass_fraction;
  frac[bi(Bone::Spine)] = seg(Segment::middle_trunk).mass_fraction;
  frac[bi(Bone::Chest)] = seg(Segment::upper_trunk).mass_fraction * (1.0 - 2.0 * kShoulderShareOfUpperTrunk);
  frac[bi(Bone::Neck)] = seg(Segment::head).mass_fraction * kNeckShareOfHead;
  frac[bi(Bone::Head)] = seg(Segment::head).mass_fraction * (1.0 - kNeckShareOfHead);
  for (const Bone s : {Bone::LeftShoulder, Bone::RightShoulder}) {
    frac[bi(s)] = seg(Segment::upper_trunk).mass_fraction * kShoulderShareOfUpperTrunk;
    frac[bi(s) + 1] = seg(Segment::upper_arm).mass_fraction;
    frac[bi(s) + 2] = seg(Segment::forearm).mass_fraction;
    frac[bi(s) + 3] = seg(Segment::hand).mass_fraction;
  }
  for (const Bone s : {Bone::LeftUpperLeg, Bone::RightUpperLeg}) {
    frac[bi(s)] = seg(Segment::thigh).mass_fraction;
    frac[bi(s) + 1] = seg(Segment::shank).mass_fraction;
    frac[bi(s) + 2] = seg(Segment::foot).mass_fraction * (1.0 - kToesShareOfFoot);
    frac[bi(s) + 3] = seg(Segment::foot).mass_fraction * kToesShareOfFoot;
  }
  // de Leva's fractions sum to 1 within rounding; normalise so the body weighs what was asked.
  double total = 0.0;
  for (const double f : frac) total += f;

  const Material& mat = spec.material;
  std::array<BodySpec, kBoneCount> bodies;
  for (size_t i = 0; i < kBoneCount; ++i) {
    const Bone bone = kBones[i].bone;
    const double m = mass * frac[i] / total;
    const Vec3 c = child_offset(bone);
    const double len = c.norm();
    const Vec3 l = c / len;
    BodySpec b;
    b.name = std::string(kBones[i].name);
    b.parent = kBones[i].parent ? static_cast<int>(bi(*kBones[i].parent)) : -1;
    b.pos_in_parent = off[i];
    b.mass_kg = m;
    const Range r = range_of(bone);
    b.joint = r.type;
    b.hinge_axis = hinge_axis(bone);
    b.limit.enabled = spec.joint_limits && r.type != JointType::free;
    b.limit.swing_max_rad = r.swing > 0.0 ? r.swing : 0.1;
    b.limit.lower_rad = r.lo;
    b.limit.upper_rad = r.hi;
    b.limit.twist_axis = l;
    b.drive.torque_limit_nm = torque_limit_70kg(bone) * mass / 70.0;

    switch (bone) {
      case Bone::Hips:
      case Bone::Spine:
      case Bone::Chest: {
        // Trunk parts: de Leva measures them top-down (proximal landmark on top).
        const Segment s = bone == Bone::Hips ? Segment::lower_trunk
                                             : (bone == Bone::Spine ? Segment::middle_trunk : Segment::upper_trunk);
        const SegmentParams p = seg(s);
        b.com = (1.0 - p.com_fraction) * c;
        b.inertia = segment_inertia(m, len, l, p.rg_sagittal, p.rg_transverse, p.rg_longitudinal);
        const double radius = (bone == Bone::Spine ? 0.050 : 0.055) * h;
        mb.add_geom(capsule_between(static_cast<int>(i), Vec3(0, -0.6 * radius, 0) + 0.5 * c,
                                    Vec3(0, 0.6 * radius, 0) + 0.5 * c, radius, mat));
        break;
      }
      case Bone::Neck:
        b.com = 0.5 * c;
        b.inertia = rod_inertia(m, 0.025 * h, len, l);
        mb.add_geom(capsule_between(static_cast<int>(i), Vec3::Zero(), c, 0.025 * h, mat));
        break;
      case Bone::Head: {
        // de Leva's head+neck centre of mass, from the vertex down; the head takes what the neck does not.
        const SegmentParams p = seg(Segment::head);
        const double neck_len = off[bi(Bone::Head)].norm();
        const double whole = neck_len + len;
        const double com_from_neck_joint = (1.0 - p.com_fraction) * whole;
        const double m_neck = mass * frac[bi(Bone::Neck)] / total;
        const double head_com = ((m + m_neck) * com_from_neck_joint - m_neck * 0.5 * neck_len) / m - neck_len;
        b.com = std::clamp(head_com, 0.2 * len, 0.8 * len) * l;
        b.inertia = segment_inertia(m, whole, l, p.rg_sagittal, p.rg_transverse, p.rg_longitudinal);
        GeomSpec g;
        g.body = static_cast<int>(i);
        g.shape = Shape::sphere(0.06 * h);
        g.local.pos = 0.5 * c;
        g.material = mat;
        mb.add_geom(g);
        break;
      }
      case Bone::LeftShoulder:
      case Bone::RightShoulder:
        b.com = 0.5 * c;
        b.inertia = rod_inertia(m, 0.025 * h, len, l);
        mb.add_geom(capsule_between(static_cast<int>(i), 0.3 * c, c, 0.025 * h, mat));
        break;
      case Bone::LeftUpperArm:
      case Bone::RightUpperArm:
      case Bone::LeftLowerArm:
      case Bone::RightLowerArm:
      case Bone::LeftUpperLeg:
      case Bone::RightUpperLeg:
      case Bone::LeftLowerLeg:
      case Bone::RightLowerLeg: {
        const bool upper_arm = bone == Bone::LeftUpperArm || bone == Bone::RightUpperArm;
        const bool lower_arm = bone == Bone::LeftLowerArm || bone == Bone::RightLowerArm;
        const bool thigh = bone == Bone::LeftUpperLeg || bone == Bone::RightUpperLeg;
        const Segment s =
            upper_arm ? Segment::upper_arm : (lower_arm ? Segment::forearm : (thigh ? Segment::thigh : Segment::shank));
        const SegmentParams p = seg(s);
        b.com = p.com_fraction * c;
        b.inertia = segment_inertia(m, len, l, p.rg_sagittal, p.rg_transverse, p.rg_longitudinal);
        const double radius = (upper_arm ? 0.025 : (lower_arm ? 0.020 : (thigh ? 0.040 : 0.030))) * h;
        mb.add_geom(capsule_between(static_cast<int>(i), Vec3::Zero(), c, radius, mat));
        break;
      }
      case Bone::LeftHand:
      case Bone::RightHand: {
        // de Leva's hand ends at the third metacarpale (WJC -> MET3); the palm box reaches the fingertips.
        const SegmentParams p = seg(Segment::hand);
        const double met3 = p.length_m / kDeLevaMaleSubject.stature_m * h;
        b.com = p.com_fraction * met3 * l;
        b.inertia = segment_inertia(m, met3, l, p.rg_sagittal, p.rg_transverse, p.rg_longitudinal);
        // The open palm faces down in the rest pose: thin along z, wide along x.
        Vec3 half = Vec3(0.025 * h, 0.025 * h, 0.012 * h);
        half += (0.5 * len - 0.025 * h) * l.cwiseAbs();
        mb.add_geom(box_at(static_cast<int>(i), 0.5 * c, half, mat));
        break;
      }
      case Bone::LeftFoot:
      case Bone::RightFoot: {
        // Sole from the heel to the toe joint; the toes body carries the rest.
        const SegmentParams p = seg(Segment::foot);
        Vec3 fwd = c;
        fwd.z() = 0.0;
        const double ahead = fwd.norm();
        fwd = ahead > 1e-9 ? Vec3(fwd / ahead) : Vec3::UnitX();
        const double sole_z = c.z() - kToeJointHeight * h;
        const double foot_len = ahead * kFootLength / kToeJointAhead;
        const Vec3 heel = -fwd * (ahead * kHeelBehindAnkle / kToeJointAhead) + Vec3(0, 0, sole_z);
        const Vec3 whole_com = heel + p.com_fraction * foot_len * fwd + Vec3(0, 0, 0.5 * -sole_z);
        const double m_toes = mass * frac[i + 1] / total;
        const Vec3 toes_com = c + 0.5 * (foot_len - (ahead + ahead * kHeelBehindAnkle / kToeJointAhead)) * fwd;
        b.com = ((m + m_toes) * whole_com - m_toes * toes_com) / m;
        b.inertia = segment_inertia(m, foot_len, fwd, p.rg_sagittal, p.rg_transverse, p.rg_longitudinal);
        const double half_h = 0.4 * -sole_z;
        const Vec3 centre = 0.5 * (heel + Vec3(c.x(), c.y(), sole_z)) + Vec3(0, 0, half_h);
        const double half_len = 0.5 * (ahead + ahead * kHeelBehindAnkle / kToeJointAhead);
        const Vec3 half =
            (half_len * fwd).cwiseAbs() + (0.0275 * h * Vec3::UnitZ().cross(fwd)).cwiseAbs() + Vec3(0, 0, half_h);
        mb.add_geom(box_at(static_cast<int>(i), centre, half, mat));
        break;
      }
      case Bone::LeftToes:
      case Bone::RightToes: {
        const Vec3 half = (0.5 * c).cwiseAbs() + Vec3(0.0, 0.0275 * h, 0.5 * kToeJointHeight * h) -
                          Vec3(0, 0.0275 * h * std::abs(l.y()), 0);
        b.com = 0.5 * c;
        b.inertia = box_inertia(m, half);
        mb.add_geom(box_at(static_cast<int>(i), Vec3(0.5 * c.x(), 0.5 * c.y(), -0.5 * kToeJointHeight * h), half, mat));
        break;
      }
    }
    bodies[i] = b;
  }
  set_default_gains(bodies, spec.drive_frequency_hz, spec.drive_damping_ratio);
  for (BodySpec& b : bodies) mb.add_body(std::move(b));
  return mb;
}

BuildResult build_humanoid(const HumanoidSpec& spec) {
  std::string error;
  const ModelBuilder mb = humanoid_builder(spec, error);
  if (!error.empty()) return {nullptr, error};
  return mb.build();
}

}  // namespace tonus::sim
