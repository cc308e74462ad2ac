// Unity's HumanBodyBones names (what /VMC/Ext/Bone/Pos carries) sorted into
// what the receiver does with them: tonus's 21 bones, UpperChest (folded into
// tonus's Chest), and the other valid names (fingers, eyes, jaw), accepted
// and not used. Anything else is not a Unity humanoid bone: malformed.
#pragma once

#include <cstdint>
#include <string_view>

#include "tonus/sim/human_bones.hpp"

namespace tonus::vmc::detail {

enum class UnityBoneKind : std::uint8_t { tonus, upper_chest, other, unknown };

struct UnityBone {
  UnityBoneKind kind = UnityBoneKind::unknown;
  sim::Bone bone = sim::Bone::Hips;  // kind == tonus only
};

UnityBone classify_unity_bone(std::string_view name);

}  // namespace tonus::vmc::detail
