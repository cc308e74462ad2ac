// Built-in joint-name tables. Names are compared after lower-casing and
// dropping any "namespace:" prefix and the characters " _-.", so
// "mixamorig:LeftUpLeg", "LeftUpLeg" and "left_up_leg" all read "leftupleg".
#include "tonus/host/balance/skeleton_map.hpp"

#include <algorithm>
#include <cctype>
#include <sstream>

namespace tonus::balance {
namespace {

using sim::Bone;

std::string normalise(std::string_view name) {
  const auto colon = name.rfind(':');
  if (colon != std::string_view::npos) name.remove_prefix(colon + 1);
  std::string out;
  for (const char c : name) {
    if (c == ' ' || c == '_' || c == '-' || c == '.') continue;
    out.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  }
  return out;
}

struct Convention {
  std::string_view name;
  std::array<std::string_view, sim::kBoneCount> joints;  // in Bone order; "" when the convention has none
};

// clang-format off
constexpr Convention kConventions[] = {
  {"CMU (cgspeed BVH)", {
    "Hips", "Spine", "Spine1", "Neck", "Head",
    "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand",
    "RightShoulder", "RightArm", "RightForeArm", "RightHand",
    "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase",
    "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase"}},
  {"Bandai Namco Research Motiondataset", {
    "Hips", "Spine", "Chest", "Neck", "Head",
    "Shoulder_L", "UpperArm_L", "LowerArm_L", "Hand_L",
    "Shoulder_R", "UpperArm_R", "LowerArm_R", "Hand_R",
    "UpperLeg_L", "LowerLeg_L", "Foot_L", "Toes_L",
    "UpperLeg_R", "LowerLeg_R", "Foot_R", "Toes_R"}},
  {"Mixamo", {
    "Hips", "Spine", "Spine1", "Neck", "Head",
    "LeftShoulder", "LeftArm", "LeftForeArm", "LeftHand",
    "RightShoulder", "RightArm", "RightForeArm", "RightHand",
    "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase",
    "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase"}},
  {"Unity HumanBodyBones", {
    "Hips", "Spine", "Chest", "Neck", "Head",
    "LeftShoulder", "LeftUpperArm", "LeftLowerArm", "LeftHand",
    "RightShoulder", "RightUpperArm", "RightLowerArm", "RightHand",
    "LeftUpperLeg", "LeftLowerLeg", "LeftFoot", "LeftToes",
    "RightUpperLeg", "RightLowerLeg", "RightFoot", "RightToes"}},
};
// clang-format on

constexpr Bone kRequired[] = {Bone::Hips,          Bone::LeftUpperArm,  Bone::LeftLowerArm,  Bone::LeftHand,
                              Bone::RightUpperArm, Bone::RightLowerArm, Bone::RightHand,     Bone::LeftUpperLeg,
                              Bone::LeftLowerLeg,  Bone::LeftFoot,      Bone::RightUpperLeg, Bone::RightLowerLeg,
                              Bone::RightFoot};

int find(const motion::Clip& clip, std::string_view name) {
  if (name.empty()) return -1;
  const std::string want = normalise(name);
  for (std::size_t j = 0; j < clip.joints.size(); ++j) {
    if (!clip.joints[j].end_site && normalise(clip.joints[j].name) == want) return static_cast<int>(j);
  }
  return -1;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front())) != 0) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back())) != 0) s.remove_suffix(1);
  return s;
}

}  // namespace

MapResult map_skeleton(const motion::Clip& clip, std::string_view override_text) {
  MapResult r;
  // The convention that finds the most bones.
  int best = -1;
  int best_count = -1;
  for (std::size_t c = 0; c < std::size(kConventions); ++c) {
    int count = 0;
    for (const std::string_view n : kConventions[c].joints) count += find(clip, n) >= 0 ? 1 : 0;
    if (count > best_count) {
      best_count = count;
      best = static_cast<int>(c);
    }
  }
  const Convention& conv = kConventions[static_cast<std::size_t>(best)];
  r.map.convention = std::string(conv.name);
  for (std::size_t b = 0; b < sim::kBoneCount; ++b) r.map.joint[b] = find(clip, conv.joints[b]);

  // Overrides: "Bone = JointName" per line.
  std::istringstream lines{std::string(override_text)};
  std::string line;
  int line_no = 0;
  bool overridden = false;
  while (std::getline(lines, line)) {
    ++line_no;
    std::string_view l = line;
    if (const auto hash = l.find('#'); hash != std::string_view::npos) l = l.substr(0, hash);
    l = trim(l);
    if (l.empty()) continue;
    const auto eq = l.find('=');
    const auto where = "mapping line " + std::to_string(line_no) + ": ";
    if (eq == std::string_view::npos) {
      r.error = where + "expected 'Bone = JointName', found '" + std::string(l) + "'";
      return r;
    }
    const std::string_view bone_name = trim(l.substr(0, eq)), joint_name = trim(l.substr(eq + 1));
    const auto bone = sim::bone_from_name(bone_name);
    if (!bone) {
      r.error = where + "'" + std::string(bone_name) + "' is not a HumanBodyBones name (e.g. LeftUpperLeg)";
      return r;
    }
    const int j = find(clip, joint_name);
    if (j < 0) {
      r.error = where + "the skeleton has no joint named '" + std::string(joint_name) + "'";
      return r;
    }
    r.map.joint[sim::index(*bone)] = j;
    overridden = true;
  }
  if (overridden) r.map.convention += " + custom";

  for (const Bone b : kRequired) {
    if (r.map.joint[sim::index(b)] < 0) {
      r.error = "the skeleton has no joint for " + std::string(sim::name(b)) + " (best match: " + r.map.convention +
                "); map it with a mapping file line '" + std::string(sim::name(b)) + " = <joint name>'";
      return r;
    }
  }
  if (r.map.joint[sim::index(Bone::Neck)] < 0 && r.map.joint[sim::index(Bone::Head)] < 0) {
    r.error = "the skeleton has neither a Neck nor a Head joint";
    return r;
  }
  for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
    if (r.map.joint[b] < 0) r.notes.push_back("no joint for " + std::string(sim::kBones[b].name) + ": synthesised");
  }
  return r;
}

}  // namespace tonus::balance
