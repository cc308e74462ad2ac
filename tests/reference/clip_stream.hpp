// A BVH clip as a VMC performer sender would stream it: its mapped bones'
// local rotations (relative to the nearest mapped ancestor, Z up, metres),
// the Hips' pose, and its own rest pose (OFFSETs, zero rotations) standing on
// the clip's floor as the source skeleton. Shared by the tests of
// BodyRetarget and BodyBalance.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "tonus/host/balance/convert.hpp"
#include "tonus/host/reference/body_retarget.hpp"

namespace tonus::reference::test {

struct ClipStream {
  balance::Conversion conv;  // the clip's own landmarks (balance's conversion)
  SourceSkeleton skeleton;
  std::vector<BodySample> samples;  // one per clip frame
};

// The nearest present ancestor of bone i in s.
int source_parent(const SourceSkeleton& s, std::size_t i);

ClipStream stream_clip(const std::string& path);

// A source skeleton's own forward kinematics (world rotations and joint positions).
struct SourcePose {
  std::array<sim::Quat, sim::kBoneCount> world{};
  std::array<sim::Vec3, sim::kBoneCount> pos{};
};
SourcePose source_fk(const SourceSkeleton& s, const BodySample& in);

}  // namespace tonus::reference::test
