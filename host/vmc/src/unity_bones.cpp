#include "unity_bones.hpp"

#include <array>

namespace tonus::vmc::detail {

namespace {

// Fingers: {Left,Right}{Thumb,Index,Middle,Ring,Little}{Proximal,Intermediate,Distal}.
bool is_finger(std::string_view n) {
  constexpr std::array<std::string_view, 2> kSides{"Left", "Right"};
  constexpr std::array<std::string_view, 5> kFingers{"Thumb", "Index", "Middle", "Ring", "Little"};
  constexpr std::array<std::string_view, 3> kSegments{"Proximal", "Intermediate", "Distal"};
  for (const std::string_view side : kSides) {
    if (!n.starts_with(side)) continue;
    const std::string_view rest = n.substr(side.size());
    for (const std::string_view finger : kFingers) {
      if (!rest.starts_with(finger)) continue;
      const std::string_view segment = rest.substr(finger.size());
      for (const std::string_view s : kSegments) {
        if (segment == s) return true;
      }
    }
  }
  return false;
}

}  // namespace

UnityBone classify_unity_bone(std::string_view name) {
  if (const std::optional<sim::Bone> b = sim::bone_from_name(name)) return {UnityBoneKind::tonus, *b};
  if (name == "UpperChest") return {UnityBoneKind::upper_chest, sim::Bone::Chest};
  if (name == "LeftEye" || name == "RightEye" || name == "Jaw" || is_finger(name)) return {UnityBoneKind::other};
  return {};
}

}  // namespace tonus::vmc::detail
