// de Leva's segments on the landmarks. Landmark pairs follow the paper's
// definitions (Table 4 with the joint-centre landmarks, see anthropometry.hpp).
#include "tonus/host/balance/mass_model.hpp"

#include <algorithm>
#include <array>
#include <span>

namespace tonus::balance {
namespace {

using sim::Bone;
using sim::Segment;

constexpr std::array<Segment, kSegmentParts> kParts = {
    Segment::head,      Segment::upper_trunk, Segment::middle_trunk, Segment::lower_trunk,
    Segment::upper_arm, Segment::upper_arm,   Segment::forearm,      Segment::forearm,
    Segment::hand,      Segment::hand,        Segment::thigh,        Segment::thigh,
    Segment::shank,     Segment::shank,       Segment::foot,         Segment::foot,
};

Vec3 at(const LandmarkFrame& f, Landmark l) { return f[index(l)]; }
Vec3 at(const LandmarkFrame& f, Bone b) { return f[sim::index(b)]; }

// A point at arc length s along a polyline.
Vec3 along(std::span<const Vec3> line, double s) {
  for (std::size_t i = 0; i + 1 < line.size(); ++i) {
    const double len = (line[i + 1] - line[i]).norm();
    if (s <= len || i + 2 == line.size())
      return len > 0.0 ? Vec3(line[i] + (line[i + 1] - line[i]) * (s / len)) : line[i];
    s -= len;
  }
  return line.back();
}

SegmentState between(const Vec3& proximal, const Vec3& distal, double com_fraction) {
  SegmentState s;
  const Vec3 d = distal - proximal;
  s.length_m = d.norm();
  s.axis = s.length_m > 1e-9 ? Vec3(d / s.length_m) : Vec3::UnitZ();
  s.com = proximal + com_fraction * d;
  return s;
}

}  // namespace

MassModel make_mass_model(double body_mass_kg, sim::Sex sex, TrunkModel trunk) {
  MassModel m;
  m.sex = sex;
  m.trunk = trunk;
  m.total_mass_kg = body_mass_kg;
  const double total = sim::total_mass_fraction(sex);  // 1 within de Leva's rounding
  for (std::size_t i = 0; i < kSegmentParts; ++i) {
    m.parts[i] = {kParts[i], body_mass_kg * sim::de_leva(kParts[i], sex).mass_fraction / total};
  }
  return m;
}

SegmentFrame place_segments(const MassModel& model, const LandmarkFrame& f) {
  const auto p = [&](Segment s) { return sim::de_leva(s, model.sex); };
  SegmentFrame out{};
  // Head: vertex (proximal) to the neck base.
  out[0] = between(at(f, Landmark::HeadTop), at(f, Bone::Neck), p(Segment::head).com_fraction);

  // Trunk: mid-hip up the spine joints to the neck base (or straight to it),
  // split at de Leva's length proportions.
  const Vec3 mid_hip = at(f, Landmark::MidHip), neck = at(f, Bone::Neck);
  const std::array<Vec3, 4> polyline{mid_hip, at(f, Bone::Spine), at(f, Bone::Chest), neck};
  const std::array<Vec3, 2> line{mid_hip, neck};
  const std::span<const Vec3> spine =
      model.trunk == TrunkModel::straight ? std::span<const Vec3>(line) : std::span<const Vec3>(polyline);
  double total = 0.0;
  for (std::size_t i = 0; i + 1 < spine.size(); ++i) total += (spine[i + 1] - spine[i]).norm();
  const double lower = p(Segment::lower_trunk).length_m, middle = p(Segment::middle_trunk).length_m,
               upper = p(Segment::upper_trunk).length_m;
  const double scale = total / (lower + middle + upper);
  const Vec3& midh = spine.front();
  const Vec3& cerv = spine.back();
  const Vec3 omph = along(spine, lower * scale), xyph = along(spine, (lower + middle) * scale);
  out[1] = between(cerv, xyph, p(Segment::upper_trunk).com_fraction);
  out[2] = between(xyph, omph, p(Segment::middle_trunk).com_fraction);
  out[3] = between(omph, midh, p(Segment::lower_trunk).com_fraction);

  const struct {
    Landmark proximal, distal;
    Segment segment;
  } limbs[] = {
      {joint_of(Bone::LeftUpperArm), joint_of(Bone::LeftLowerArm), Segment::upper_arm},
      {joint_of(Bone::RightUpperArm), joint_of(Bone::RightLowerArm), Segment::upper_arm},
      {joint_of(Bone::LeftLowerArm), joint_of(Bone::LeftHand), Segment::forearm},
      {joint_of(Bone::RightLowerArm), joint_of(Bone::RightHand), Segment::forearm},
      {joint_of(Bone::LeftHand), Landmark::LeftHandTip, Segment::hand},
      {joint_of(Bone::RightHand), Landmark::RightHandTip, Segment::hand},
      {joint_of(Bone::LeftUpperLeg), joint_of(Bone::LeftLowerLeg), Segment::thigh},
      {joint_of(Bone::RightUpperLeg), joint_of(Bone::RightLowerLeg), Segment::thigh},
      {joint_of(Bone::LeftLowerLeg), joint_of(Bone::LeftFoot), Segment::shank},
      {joint_of(Bone::RightLowerLeg), joint_of(Bone::RightFoot), Segment::shank},
      {Landmark::LeftHeel, Landmark::LeftToeTip, Segment::foot},
      {Landmark::RightHeel, Landmark::RightToeTip, Segment::foot},
  };
  for (std::size_t i = 0; i < 12; ++i) {
    out[4 + i] = between(at(f, limbs[i].proximal), at(f, limbs[i].distal), p(limbs[i].segment).com_fraction);
  }
  return out;
}

Vec3 centre_of_mass(const MassModel& model, const SegmentFrame& segments) {
  Vec3 c = Vec3::Zero();
  double m = 0.0;
  for (std::size_t i = 0; i < kSegmentParts; ++i) {
    c += model.parts[i].mass_kg * segments[i].com;
    m += model.parts[i].mass_kg;
  }
  return m > 0.0 ? Vec3(c / m) : c;
}

}  // namespace tonus::balance
