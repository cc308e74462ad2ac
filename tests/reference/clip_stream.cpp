#include "clip_stream.hpp"

#include <doctest/doctest.h>

#include "reference_checks.hpp"
#include "tonus/host/balance/contacts.hpp"
#include "tonus/host/motion/bvh.hpp"

namespace tonus::reference::test {
namespace {

using sim::Bone;
using sim::Vec3;
constexpr std::size_t kN = sim::kBoneCount;

std::size_t bi(Bone b) { return sim::index(b); }
std::size_t parent_of(std::size_t i) { return sim::index(*sim::kBones[i].parent); }

}  // namespace

int source_parent(const SourceSkeleton& s, std::size_t i) {
  std::size_t p = parent_of(i);
  while (!s.present[p]) p = parent_of(p);
  return static_cast<int>(p);
}

SourcePose source_fk(const SourceSkeleton& s, const BodySample& in) {
  SourcePose f;
  f.world[0] = in.root_rotation;
  f.pos[0] = in.root_position;
  for (std::size_t i = 1; i < kN; ++i) {
    if (!s.present[i]) continue;
    const auto p = static_cast<std::size_t>(source_parent(s, i));
    f.world[i] = f.world[p] * in.local[i];
    f.pos[i] = f.pos[p] + f.world[p] * s.offset[i];
  }
  return f;
}

ClipStream stream_clip(const std::string& path) {
  ClipStream out;
  out.conv = load(path);
  const motion::ReadResult read = motion::read_bvh_file(path);
  REQUIRE(read.ok());
  const motion::Clip& clip = read.clip;
  const balance::SkeletonGeometry& g = out.conv.geometry;
  const balance::HumanMotion& motion = out.conv.motion;

  // Rest joint positions (zero rotations), internal frame, metres.
  std::vector<Vec3> rest(clip.joints.size(), Vec3::Zero());
  for (std::size_t j = 0; j < clip.joints.size(); ++j) {
    const int p = clip.joints[j].parent;
    const Eigen::Vector3d o = clip.joints[j].offset * g.metres_per_unit;
    rest[j] = (p >= 0 ? rest[static_cast<std::size_t>(p)] : Vec3::Zero()) + Vec3(o.z(), o.x(), o.y());
  }
  SourceSkeleton& src = out.skeleton;
  for (std::size_t i = 0; i < kN; ++i) src.present[i] = g.map.joint[i] >= 0;
  const auto joint_rest = [&](std::size_t bone) { return rest[static_cast<std::size_t>(g.map.joint[bone])]; };
  for (std::size_t i = 1; i < kN; ++i) {
    if (src.present[i]) src.offset[i] = joint_rest(i) - joint_rest(static_cast<std::size_t>(source_parent(src, i)));
  }
  // Where the clip's floor is: its ankles' median height while a flat foot
  // stands (balance's contacts); standing straight, the mid-hip is a leg
  // length (hip to ankle) above that.
  const balance::ContactTrack contacts = balance::detect_contacts(motion, balance::ContactOptions{});
  std::vector<double> ankle_z;
  for (std::size_t f = motion.first_frame; f < motion.size() && f < contacts.frames.size(); ++f) {
    for (std::size_t k = 0; k < 2; ++k) {
      if (contacts.frames[f][k].heel && contacts.frames[f][k].ball)
        ankle_z.push_back(motion.frames[f].p[bi(k == 0 ? Bone::LeftFoot : Bone::RightFoot)].z());
    }
  }
  REQUIRE(!ankle_z.empty());
  const double standing_ankle_z = spread(ankle_z).median;
  const auto leg = [&](Bone thigh) {
    const std::size_t t = bi(thigh);
    return (joint_rest(t + 1) - joint_rest(t)).norm() + (joint_rest(t + 2) - joint_rest(t + 1)).norm();
  };
  const double leg_m = 0.5 * (leg(Bone::LeftUpperLeg) + leg(Bone::RightUpperLeg));
  const Vec3 hip_mid_offset = 0.5 * (src.offset[bi(Bone::LeftUpperLeg)] + src.offset[bi(Bone::RightUpperLeg)]);
  src.offset[0] = Vec3(0.0, 0.0, standing_ankle_z + leg_m - hip_mid_offset.z());

  BodySample in;
  in.present = src.present;
  in.root_present = true;
  out.samples.reserve(motion.size());
  for (const balance::MotionFrame& fr : motion.frames) {
    for (std::size_t i = 1; i < kN; ++i) {
      if (src.present[i])
        in.local[i] = fr.rotation[static_cast<std::size_t>(source_parent(src, i))].conjugate() * fr.rotation[i];
    }
    in.root_position = fr.p[0];
    in.root_rotation = fr.rotation[0];
    out.samples.push_back(in);
  }
  return out;
}

}  // namespace tonus::reference::test
