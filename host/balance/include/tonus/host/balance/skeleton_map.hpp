// Which joint of a BVH skeleton is which HumanBodyBones bone. Built in, by
// joint names (case-insensitive, namespace and asset prefixes such as
// "mixamorig:", "Character1_", "Skeleton_", "DEF-" ignored): MotionBuilder
// HumanIK, CMU (cgspeed's MotionBuilder-friendly release), Mixamo,
// Perception Neuron, Rokoko, Xsens MVN, Unity HumanBodyBones, VRM (J_Bip_*),
// Bandai Namco's motion datasets, Blender Rigify, 3dsMax Biped, Daz and
// OptiTrack Motive; the convention that finds the most bones wins. When the
// names give fewer than half the required bones, the skeleton's rest pose is
// used instead (convention "topology"): legs to the lowest ends, arms to the
// ends farthest to the sides, the head to the highest end. A small mapping
// text overrides or adds entries, one per line, the bone first:
// `LeftUpperLeg = Thigh_L` ('#' starts a comment).
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "tonus/host/motion/clip.hpp"
#include "tonus/sim/human_bones.hpp"

namespace tonus::balance {

struct SkeletonMap {
  std::string convention;                    // the built-in table used ("Xsens MVN", "topology", ...), + " + custom"
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
