#include "synthetic_body.hpp"

#include <string>
#include <vector>

namespace tonus::balance::test {

namespace {

using motion::Channel;

struct Bone {
  const char* cmu;
  const char* bandai;
  int parent;
  Eigen::Vector3d offset;  // cm, from the parent
};

// Left is +x; the right side mirrors it.
const std::vector<Bone>& bones() {
  static const std::vector<Bone> b{
      {"Hips", "Hips", -1, {0, 0, 0}},
      {"LeftUpLeg", "UpperLeg_L", 0, {9, -3, 0}},
      {"LeftLeg", "LowerLeg_L", 1, {0, -42, 0}},
      {"LeftFoot", "Foot_L", 2, {0, -42, 0}},
      {"LeftToeBase", "Toes_L", 3, {0, -6, 14}},
      {"RightUpLeg", "UpperLeg_R", 0, {-9, -3, 0}},
      {"RightLeg", "LowerLeg_R", 5, {0, -42, 0}},
      {"RightFoot", "Foot_R", 6, {0, -42, 0}},
      {"RightToeBase", "Toes_R", 7, {0, -6, 14}},
      {"Spine", "Spine", 0, {0, 10, 0}},
      {"Spine1", "Chest", 9, {0, 20, 0}},
      {"Neck", "Neck", 10, {0, 20, 0}},
      {"Head", "Head", 11, {0, 10, 0}},
      {"LeftArm", "UpperArm_L", 10, {18, 17, 0}},
      {"LeftForeArm", "LowerArm_L", 13, {0, -30, 0}},
      {"LeftHand", "Hand_L", 14, {0, -26, 2}},
      {"RightArm", "UpperArm_R", 10, {-18, 17, 0}},
      {"RightForeArm", "LowerArm_R", 16, {0, -30, 0}},
      {"RightHand", "Hand_R", 17, {0, -26, 2}},
  };
  return b;
}

}  // namespace

motion::Clip synthetic_body(std::size_t frames, Names names,
                            const std::function<Eigen::Vector3d(double)>& root_offset) {
  motion::Clip clip;
  for (const Bone& b : bones()) {
    motion::Joint j;
    j.name = names == Names::cmu ? b.cmu : b.bandai;
    j.parent = b.parent;
    j.offset = b.offset;
    if (b.parent < 0) j.channels = {Channel::x_position, Channel::y_position, Channel::z_position};
    j.channels.insert(j.channels.end(), {Channel::z_rotation, Channel::y_rotation, Channel::x_rotation});
    clip.joints.push_back(j);
  }
  clip.frame_time_s = 1.0 / 120.0;
  clip.frame_count = frames;
  const std::size_t columns = clip.channel_count();
  clip.values.assign(frames * columns, 0.0);
  for (std::size_t f = 0; f < frames; ++f) {
    const Eigen::Vector3d root = Eigen::Vector3d(0, 95, 0) + root_offset(static_cast<double>(f) * clip.frame_time_s);
    for (std::size_t a = 0; a < 3; ++a) clip.values[f * columns + a] = root[static_cast<Eigen::Index>(a)];
  }
  return clip;
}

}  // namespace tonus::balance::test
