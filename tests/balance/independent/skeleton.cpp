#include "independent/skeleton.hpp"

#include <algorithm>
#include <cctype>
#include <string_view>

#include "tonus/host/motion/kinematics.hpp"

namespace tonus::indep {

namespace {

struct Names {
  std::string_view what;
  std::string_view cmu;
  std::string_view bandai;
};

// Indexed by Site.
constexpr std::array<Names, kSiteCount> kNames{{
    {"neck", "Neck", "Neck"},
    {"head", "Head", "Head"},
    {"left hip", "LeftUpLeg", "UpperLeg_L"},
    {"left knee", "LeftLeg", "LowerLeg_L"},
    {"left ankle", "LeftFoot", "Foot_L"},
    {"left toes", "LeftToeBase", "Toes_L"},
    {"left shoulder", "LeftArm", "UpperArm_L"},
    {"left elbow", "LeftForeArm", "LowerArm_L"},
    {"left wrist", "LeftHand", "Hand_L"},
    {"right hip", "RightUpLeg", "UpperLeg_R"},
    {"right knee", "RightLeg", "LowerLeg_R"},
    {"right ankle", "RightFoot", "Foot_R"},
    {"right toes", "RightToeBase", "Toes_R"},
    {"right shoulder", "RightArm", "UpperArm_R"},
    {"right elbow", "RightForeArm", "LowerArm_R"},
    {"right wrist", "RightHand", "Hand_R"},
}};

bool same_name(std::string_view a, std::string_view b) {
  return std::ranges::equal(a, b, [](char x, char y) {
    return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
  });
}

}  // namespace

SkeletonMap map_skeleton(const motion::Clip& clip) {
  SkeletonMap map;
  for (std::size_t s = 0; s < kSiteCount; ++s) {
    const auto found = std::ranges::find_if(clip.joints, [&](const motion::Joint& j) {
      return !j.end_site && (same_name(j.name, kNames[s].cmu) || same_name(j.name, kNames[s].bandai));
    });
    if (found != clip.joints.end()) {
      map.joint[s] = static_cast<std::size_t>(found - clip.joints.begin());
      continue;
    }
    map.error += map.error.empty() ? "skeleton not recognised: no joint for " : ", ";
    map.error +=
        std::string(kNames[s].what) + " (" + std::string(kNames[s].cmu) + " or " + std::string(kNames[s].bandai) + ")";
  }
  return map;
}

Vec3 to_internal(const Eigen::Vector3d& file, double metres_per_unit) {
  return metres_per_unit * Vec3(file.x(), -file.z(), file.y());
}

std::vector<Sites> site_positions(const motion::Clip& clip, const SkeletonMap& map, double metres_per_unit,
                                  std::size_t first_frame) {
  std::vector<Sites> out;
  std::vector<motion::JointPose> poses;
  for (std::size_t f = first_frame; f < clip.frame_count; ++f) {
    if (!motion::forward_kinematics(clip, f, poses)) return {};
    Sites s;
    for (std::size_t i = 0; i < kSiteCount; ++i) s[i] = to_internal(poses[map.joint[i]].position, metres_per_unit);
    out.push_back(s);
  }
  return out;
}

}  // namespace tonus::indep
