// The humanoid's bones, named as Unity's HumanBodyBones (the names avatar
// engines and the VMC protocol use). Shared by the physics model (sim/), the
// motion I/O and the balance filter (host/), so a bone means the same thing
// everywhere.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace tonus::sim {

// Order is parent-before-child (a valid topological order of the tree), so
// arrays indexed by Bone can be walked root to leaves in one pass.
enum class Bone : std::uint8_t {
  Hips = 0,  // root
  Spine,
  Chest,
  Neck,
  Head,
  LeftShoulder,
  LeftUpperArm,
  LeftLowerArm,
  LeftHand,
  RightShoulder,
  RightUpperArm,
  RightLowerArm,
  RightHand,
  LeftUpperLeg,
  LeftLowerLeg,
  LeftFoot,
  LeftToes,
  RightUpperLeg,
  RightLowerLeg,
  RightFoot,
  RightToes,
};

inline constexpr std::size_t kBoneCount = 21;  // root + 20 joints

enum class Side : std::uint8_t { center, left, right };

struct BoneInfo {
  Bone bone;
  std::string_view name;  // Unity HumanBodyBones spelling
  std::optional<Bone> parent;
  Side side;
};

// clang-format off
inline constexpr std::array<BoneInfo, kBoneCount> kBones{{
  {Bone::Hips,          "Hips",          std::nullopt,        Side::center},
  {Bone::Spine,         "Spine",         Bone::Hips,          Side::center},
  {Bone::Chest,         "Chest",         Bone::Spine,         Side::center},
  {Bone::Neck,          "Neck",          Bone::Chest,         Side::center},
  {Bone::Head,          "Head",          Bone::Neck,          Side::center},
  {Bone::LeftShoulder,  "LeftShoulder",  Bone::Chest,         Side::left},
  {Bone::LeftUpperArm,  "LeftUpperArm",  Bone::LeftShoulder,  Side::left},
  {Bone::LeftLowerArm,  "LeftLowerArm",  Bone::LeftUpperArm,  Side::left},
  {Bone::LeftHand,      "LeftHand",      Bone::LeftLowerArm,  Side::left},
  {Bone::RightShoulder, "RightShoulder", Bone::Chest,         Side::right},
  {Bone::RightUpperArm, "RightUpperArm", Bone::RightShoulder, Side::right},
  {Bone::RightLowerArm, "RightLowerArm", Bone::RightUpperArm, Side::right},
  {Bone::RightHand,     "RightHand",     Bone::RightLowerArm, Side::right},
  {Bone::LeftUpperLeg,  "LeftUpperLeg",  Bone::Hips,          Side::left},
  {Bone::LeftLowerLeg,  "LeftLowerLeg",  Bone::LeftUpperLeg,  Side::left},
  {Bone::LeftFoot,      "LeftFoot",      Bone::LeftLowerLeg,  Side::left},
  {Bone::LeftToes,      "LeftToes",      Bone::LeftFoot,      Side::left},
  {Bone::RightUpperLeg, "RightUpperLeg", Bone::Hips,          Side::right},
  {Bone::RightLowerLeg, "RightLowerLeg", Bone::RightUpperLeg, Side::right},
  {Bone::RightFoot,     "RightFoot",     Bone::RightLowerLeg, Side::right},
  {Bone::RightToes,     "RightToes",     Bone::RightFoot,     Side::right},
}};
// clang-format on

constexpr std::size_t index(Bone b) { return static_cast<std::size_t>(b); }
constexpr const BoneInfo& info(Bone b) { return kBones[index(b)]; }
constexpr std::string_view name(Bone b) { return info(b).name; }

// Exact (case-sensitive) HumanBodyBones name to bone.
constexpr std::optional<Bone> bone_from_name(std::string_view n) {
  for (const BoneInfo& b : kBones) {
    if (b.name == n) return b.bone;
  }
  return std::nullopt;
}

// The same bone on the other side (itself for centre bones).
constexpr Bone mirror(Bone b) {
  const std::size_t i = index(b);
  if (kBones[i].side == Side::center) return b;
  constexpr std::size_t kArm = index(Bone::RightShoulder) - index(Bone::LeftShoulder);
  constexpr std::size_t kLeg = index(Bone::RightUpperLeg) - index(Bone::LeftUpperLeg);
  if (i >= index(Bone::LeftShoulder) && i <= index(Bone::LeftHand)) return static_cast<Bone>(i + kArm);
  if (i >= index(Bone::RightShoulder) && i <= index(Bone::RightHand)) return static_cast<Bone>(i - kArm);
  if (i >= index(Bone::LeftUpperLeg) && i <= index(Bone::LeftToes)) return static_cast<Bone>(i + kLeg);
  return static_cast<Bone>(i - kLeg);
}

}  // namespace tonus::sim
