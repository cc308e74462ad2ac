// World frames of the humanoid's bones from their world rotations: a child's
// joint sits at its parent's joint plus the parent's rotation of its rest
// offset (the humanoid's rest frames are parallel to the world).
#pragma once

#include <array>

#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/math.hpp"

namespace tonus::reference::detail {

struct BodyFrames {
  std::array<sim::Vec3, sim::kBoneCount> pos{};
  std::array<sim::Quat, sim::kBoneCount> rot{};
};

inline void place_bones(const std::array<sim::Vec3, sim::kBoneCount>& offset, const sim::Vec3& root_pos,
                        BodyFrames& f) {
  f.pos[0] = root_pos;
  for (std::size_t i = 1; i < sim::kBoneCount; ++i) {
    const std::size_t p = sim::index(*sim::kBones[i].parent);
    f.pos[i] = f.pos[p] + f.rot[p] * offset[i];
  }
}

inline sim::Quat yaw_quat(double yaw_rad) { return sim::Quat(Eigen::AngleAxisd(yaw_rad, sim::Vec3::UnitZ())); }

inline sim::Vec3 horizontal(const sim::Vec3& v) { return {v.x(), v.y(), 0.0}; }

}  // namespace tonus::reference::detail
