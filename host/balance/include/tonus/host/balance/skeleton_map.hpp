// Which joint of a BVH skeleton is which HumanBodyBones bone. Built in: the
// CMU conventions (cgspeed's MotionBuilder-friendly release), Bandai Namco's
// motion datasets, Mixamo (any "mixamorig<N>:" prefix) and Unity's own names;
// the best-matching convention wins. A small mapping text overrides or adds
// entries, one per line, the bone first: `LeftUpperLeg = Thigh_L` ('#' starts
// a comment).
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "tonus/host/motion/clip.hpp"
#include "tonus/sim/human_bones.hpp"

namespace tonus::balance {

struct SkeletonMap {
  std::string convention;                    // the built-in table used, or "custom"
  std::array<int, sim::kBoneCount> joint{};  // the clip's joint index per bone; -1 when the skeleton lacks it
};

struct MapResult {
  SkeletonMap map;
  std::string error;  // non-empty: a required bone is missing or the override text is malformed
  std::vector<std::string> notes;
  [[nodiscard]] bool ok() const { return error.empty(); }
};

// Bones the analysis cannot do without: hips, legs down to the feet, arms
// down to the hands, and the head or the neck.
MapResult map_skeleton(const motion::Clip& clip, std::string_view override_text = {});

}  // namespace tonus::balance
