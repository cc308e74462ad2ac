// The waist correction of one frame: the pelvis and everything above turn
// about the midpoint of the hip joints (so pitching leaves both hip joints in
// place; the root joint moves with the turn), lowered by the few millimetres a
// straight stance leg needs to still reach its foot; each leg is re-solved by
// two-bone IK between its moved hip joint and its unmoved ankle, the knee
// staying in its captured plane.
#include <algorithm>
#include <cmath>

#include "tonus/host/balance/filter.hpp"
#include "tonus/sim/math.hpp"

namespace tonus::balance {
namespace {

using sim::Bone;

constexpr Bone kUpper[] = {Bone::Hips,      Bone::Spine,         Bone::Chest,         Bone::Neck,
                           Bone::Head,      Bone::LeftShoulder,  Bone::LeftUpperArm,  Bone::LeftLowerArm,
                           Bone::LeftHand,  Bone::RightShoulder, Bone::RightUpperArm, Bone::RightLowerArm,
                           Bone::RightHand, Bone::LeftUpperLeg,  Bone::RightUpperLeg};
constexpr Landmark kUpperExtras[] = {Landmark::HeadTop, Landmark::LeftHandTip, Landmark::RightHandTip,
                                     Landmark::MidHip};

Quat exp_map(const Vec3& v) {
  const double a = v.norm();
  if (a < 1e-12) return Quat::Identity();
  return Quat(Eigen::AngleAxisd(a, v / a));
}

struct Leg {
  Bone thigh, shank, ankle, toes;
  Landmark toe_tip, heel;
};
constexpr Leg kLegs[2] = {
    {Bone::LeftUpperLeg, Bone::LeftLowerLeg, Bone::LeftFoot, Bone::LeftToes, Landmark::LeftToeTip, Landmark::LeftHeel},
    {Bone::RightUpperLeg, Bone::RightLowerLeg, Bone::RightFoot, Bone::RightToes, Landmark::RightToeTip,
     Landmark::RightHeel}};

Vec3 at(const MotionFrame& f, Bone b) { return f.p[sim::index(b)]; }

}  // namespace

double leg_reach_m(const Vec3& hip, const Vec3& knee, const Vec3& ankle) {
  constexpr double kReach = 0.999;
  return std::max(kReach * ((knee - hip).norm() + (ankle - knee).norm()), (ankle - hip).norm());
}

Vec3 WaistTurn::ankle_target(const Vec3& ankle, std::size_t leg) const {
  return ankle + follow[leg] * (pivot + rotation * (ankle - pivot) + shift - Vec3(0, 0, drop_m) - ankle);
}

Quat WaistTurn::foot_turn(std::size_t leg) const { return Quat::Identity().slerp(follow[leg], rotation); }

Vec3 WaistTurn::knee_side(const MotionFrame& in, std::size_t li, const Vec3& hip2, const Vec3& ankle2) const {
  // The toes' pull once the hip has moved kPullFrom_m or more (less in
  // proportion): a captured bend this small or smaller counts for little
  // beside it (a knee is rarely straighter than this in a stance).
  constexpr double kToesPull_m = 0.01, kPullFrom_m = 0.01;
  const Leg& leg = kLegs[li];
  const Vec3 hip = at(in, leg.thigh), knee = at(in, leg.shank), ankle = at(in, leg.ankle);
  const Vec3 line = ankle2 - hip2;
  const Vec3 u = line.normalized();
  const auto square = [&](const Vec3& v) { return Vec3(v - v.dot(u) * u); };
  const Vec3 line0 = ankle - hip;
  Vec3 bend = knee - hip;
  if (line0.squaredNorm() > 1e-18) bend -= bend.dot(line0) / line0.squaredNorm() * line0;
  Vec3 toes = in.p[index(leg.toe_tip)] - ankle;
  toes.z() = 0.0;
  const double pull = kToesPull_m * std::min(1.0, (hip2 - hip).norm() / kPullFrom_m);
  if (toes.norm() > 1e-9) bend += pull * toes.normalized();
  // Carried as the foot is (a following foot's leg turns with the pelvis),
  // then by the least turn from the captured line to the new one.
  const Quat carry = foot_turn(li);
  Vec3 v = square(sim::quat_from_two_vectors(carry * line0, line) * (carry * bend));
  if (v.norm() < 1e-9) v = square(knee - hip);
  if (v.norm() < 1e-9) v = u.unitOrthogonal();
  return v.normalized();
}

WaistTurn waist_turn(const MotionFrame& in, const Vec3& delta, const Vec2& shift_m, const std::array<double, 2>& follow,
                     double min_drop_m) {
  WaistTurn w;
  w.rotation = exp_map(delta);
  w.pivot = in.p[index(Landmark::MidHip)];
  w.shift = Vec3(shift_m.x(), shift_m.y(), 0.0);
  w.follow = follow;
  // The vertical shift of the pelvis, closest to none, that keeps both hips
  // within reach of their ankles (leg_reach_m): each leg allows an
  // interval of shifts; take the common one.
  double lo = -1e9, hi = 1e9;
  for (std::size_t li = 0; li < 2; ++li) {
    const Leg& leg = kLegs[li];
    const Vec3 hip = at(in, leg.thigh), knee = at(in, leg.shank), ankle = at(in, leg.ankle);
    const double reach = leg_reach_m(hip, knee, ankle);
    // Before any vertical shift s (up); a partly following foot rises with the
    // pelvis by its share, so the leg sees k s of it.
    if (w.follow[li] >= 1.0) continue;  // the leg moves rigidly with the pelvis
    const Vec3 d = w.pivot + w.rotation * (hip - w.pivot) + w.shift - w.ankle_target(ankle, li);
    const double k = 1.0 - w.follow[li];
    const double horizontal2 = d.x() * d.x() + d.y() * d.y();
    if (horizontal2 >= reach * reach) {  // out of reach whatever the height
      w.reachable = false;
      continue;
    }
    const double half = std::sqrt(reach * reach - horizontal2);
    lo = std::max(lo, (-half - d.z()) / k);
    hi = std::min(hi, (half - d.z()) / k);
  }
  if (lo > hi) {
    w.reachable = false;
    w.drop_m = -0.5 * (lo + hi);  // as close to both as a single shift gets
  } else {
    w.drop_m = -std::clamp(-std::max(min_drop_m, 0.0), lo, hi);
  }
  return w;
}

MotionFrame rotate_waist(const MotionFrame& in, const Vec3& delta, double* drop_m, bool* reachable) {
  return correct_waist(in, delta, Vec2::Zero(), drop_m, reachable);
}

MotionFrame correct_waist(const MotionFrame& in, const Vec3& delta, const Vec2& shift_m, double* drop_m,
                          bool* reachable, const std::array<double, 2>& follow, double min_drop_m) {
  const WaistTurn w = waist_turn(in, delta, shift_m, follow, min_drop_m);
  if (drop_m != nullptr) *drop_m = w.drop_m;
  if (reachable != nullptr) *reachable = w.reachable;
  MotionFrame out = in;
  const Vec3 down(0, 0, w.drop_m);
  const auto move = [&](const Vec3& p) { return Vec3(w.pivot + w.rotation * (p - w.pivot) + w.shift - down); };
  for (const Bone b : kUpper) {
    out.p[sim::index(b)] = move(in.p[sim::index(b)]);
    if (b != Bone::LeftUpperLeg && b != Bone::RightUpperLeg)
      out.rotation[sim::index(b)] = w.rotation * in.rotation[sim::index(b)];
  }
  for (const Landmark l : kUpperExtras) out.p[index(l)] = move(in.p[index(l)]);

  for (std::size_t li = 0; li < 2; ++li) {
    const Leg& leg = kLegs[li];
    const Vec3 hip = at(in, leg.thigh), knee = at(in, leg.shank), ankle = at(in, leg.ankle);
    const Vec3 hip2 = out.p[sim::index(leg.thigh)];
    // A swinging foot follows the pelvis by its share; a planted one stays.
    const Vec3 ankle2 = w.ankle_target(ankle, li);
    const Quat foot_turn = w.foot_turn(li);
    if (w.follow[li] > 0.0) {
      for (const Bone b : {leg.ankle, leg.toes}) {
        out.p[sim::index(b)] = ankle2 + foot_turn * (in.p[sim::index(b)] - ankle);
        out.rotation[sim::index(b)] = foot_turn * in.rotation[sim::index(b)];
      }
      for (const Landmark l : {leg.toe_tip, leg.heel}) out.p[index(l)] = ankle2 + foot_turn * (in.p[index(l)] - ankle);
    }
    const double l1 = (knee - hip).norm(), l2 = (ankle - knee).norm();
    const Vec3 d = ankle2 - hip2;
    const double dist = std::min(d.norm(), l1 + l2);
    if (dist < 1e-9) continue;
    const Vec3 u = d.normalized();
    const double a = (l1 * l1 - l2 * l2 + dist * dist) / (2.0 * dist);
    const double h = std::sqrt(std::max(l1 * l1 - a * a, 0.0));
    const Vec3 v = w.knee_side(in, li, hip2, ankle2);
    const Vec3 knee2 = hip2 + a * u + h * v;
    out.p[sim::index(leg.shank)] = knee2;
    out.rotation[sim::index(leg.thigh)] =
        sim::quat_from_two_vectors(knee - hip, knee2 - hip2) * in.rotation[sim::index(leg.thigh)];
    out.rotation[sim::index(leg.shank)] =
        sim::quat_from_two_vectors(ankle - knee, ankle2 - knee2) * in.rotation[sim::index(leg.shank)];
  }
  return out;
}

}  // namespace tonus::balance
