// The waist rotation of one frame: the pelvis and everything above turn about
// the midpoint of the hip joints (so that pitching the pelvis leaves both hip
// joints in place, and the root joint moves with the turn); each leg is
// re-solved by two-bone IK between its moved hip joint and its unmoved ankle,
// the knee staying in its captured plane.
#include <cmath>

#include "tonus/host/balance/filter.hpp"

namespace tonus::balance {
namespace {

using sim::Bone;

constexpr Bone kUpper[] = {Bone::Hips,      Bone::Spine,         Bone::Chest,         Bone::Neck,
                           Bone::Head,      Bone::LeftShoulder,  Bone::LeftUpperArm,  Bone::LeftLowerArm,
                           Bone::LeftHand,  Bone::RightShoulder, Bone::RightUpperArm, Bone::RightLowerArm,
                           Bone::RightHand, Bone::LeftUpperLeg,  Bone::RightUpperLeg};
constexpr Landmark kUpperExtras[] = {Landmark::HeadTop, Landmark::LeftHandTip, Landmark::RightHandTip,
                                     Landmark::MidHip};

// A leg is kept from straightening beyond this share of its length, which
// would leave the IK no room (the filter penalises going past it).
constexpr double kReach = 0.999;

Quat exp_map(const Vec3& v) {
  const double a = v.norm();
  if (a < 1e-12) return Quat::Identity();
  return Quat(Eigen::AngleAxisd(a, v / a));
}

}  // namespace

MotionFrame rotate_waist(const MotionFrame& in, const Vec3& delta, bool& reachable, double* overreach_m) {
  reachable = true;
  if (overreach_m != nullptr) overreach_m[0] = overreach_m[1] = 0.0;
  MotionFrame out = in;
  const Quat r = exp_map(delta);
  const Vec3 c = in.p[index(Landmark::MidHip)];
  for (const Bone b : kUpper) {
    out.p[sim::index(b)] = c + r * (in.p[sim::index(b)] - c);
    if (b != Bone::LeftUpperLeg && b != Bone::RightUpperLeg)
      out.rotation[sim::index(b)] = r * in.rotation[sim::index(b)];
  }
  for (const Landmark l : kUpperExtras) out.p[index(l)] = c + r * (in.p[index(l)] - c);

  for (const Foot foot : {Foot::left, Foot::right}) {
    const Bone thigh = foot == Foot::left ? Bone::LeftUpperLeg : Bone::RightUpperLeg;
    const Bone shank = foot == Foot::left ? Bone::LeftLowerLeg : Bone::RightLowerLeg;
    const Bone ankle_bone = foot == Foot::left ? Bone::LeftFoot : Bone::RightFoot;
    const Vec3 hip = in.p[sim::index(thigh)], knee = in.p[sim::index(shank)], ankle = in.p[sim::index(ankle_bone)];
    const Vec3 hip2 = out.p[sim::index(thigh)];
    const double l1 = (knee - hip).norm(), l2 = (ankle - knee).norm();
    Vec3 d = ankle - hip2;
    double dist = d.norm();
    if (dist < 1e-9) continue;
    const Vec3 u = d / dist;
    if (overreach_m != nullptr) overreach_m[static_cast<std::size_t>(foot)] = dist - kReach * (l1 + l2);
    if (dist > l1 + l2) {
      reachable = false;  // the knee straightens; the foot cannot be kept
      dist = l1 + l2;
    }
    const double a = (l1 * l1 - l2 * l2 + dist * dist) / (2.0 * dist);
    const double h = std::sqrt(std::max(l1 * l1 - a * a, 0.0));
    Vec3 v = (knee - hip2) - (knee - hip2).dot(u) * u;  // towards the captured knee
    if (v.norm() < 1e-9) v = u.unitOrthogonal();
    v.normalize();
    const Vec3 knee2 = hip2 + a * u + h * v;
    out.p[sim::index(shank)] = knee2;
    out.rotation[sim::index(thigh)] = Quat::FromTwoVectors(knee - hip, knee2 - hip2) * in.rotation[sim::index(thigh)];
    out.rotation[sim::index(shank)] =
        Quat::FromTwoVectors(ankle - knee, ankle - knee2) * in.rotation[sim::index(shank)];
  }
  return out;
}

}  // namespace tonus::balance
