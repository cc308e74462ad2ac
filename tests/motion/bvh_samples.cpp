#include "bvh_samples.hpp"

#include <random>

namespace tonus::test {

const char* const kSmallBvh =
    "HIERARCHY\n"
    "ROOT Hips\n"
    "{\n"
    "\tOFFSET 0.5 1.5 -2.5\n"
    "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n"
    "\tJOINT Chest\n"
    "\t{\n"
    "\t\tOFFSET 0 10 0\n"
    "\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n"
    "\t\tEnd Site\n"
    "\t\t{\n"
    "\t\t\tOFFSET 0 5 0\n"
    "\t\t}\n"
    "\t}\n"
    "}\n"
    "MOTION\n"
    "Frames: 3\n"
    "Frame Time: 0.0333333\n"
    "1 2 3 4 5 6 7 8 9\n"
    "-1 -2 -3 -4 -5 -6 -7 -8 -9\n"
    "0.5 .25 -0.00000 1e1 7.7e-06 0 0 0 90\n";

const std::array<const char*, 7> kSharedClips = {
    "cmu_02_walk.bvh",
    "cmu_01_01_jumps.bvh",
    "dataset-1_walk_normal_001.bvh",
    "dataset-1_kick_normal_001.bvh",
    "dataset-1_punch_normal_001.bvh",
    "dataset-2_run_normal_010.bvh",
    "dataset-2_wave-both-hands_normal_001.bvh",
};

std::string shared_bvh(const std::string& name) { return std::string(TONUS_SHARED_DATA_DIR) + "/bvh/" + name; }

motion::Clip synthetic_clip(std::size_t frame_count, unsigned seed) {
  using motion::Channel;
  motion::Clip clip;
  motion::Joint root;
  root.name = "Root";
  root.offset = {0.25, -1.0, 3.0};
  root.channels = {Channel::y_rotation, Channel::x_position, Channel::z_rotation,
                   Channel::y_position, Channel::x_rotation, Channel::z_position};
  motion::Joint arm;
  arm.name = "Left Arm";  // a blank inside a name, as 3ds Max writes them
  arm.parent = 0;
  arm.offset = {1.0, 0.0, -0.5};
  arm.channels = {Channel::x_rotation, Channel::z_rotation, Channel::y_rotation};
  motion::Joint site;
  site.name = "Left Arm_End";
  site.parent = 1;
  site.offset = {2.0, 0.0, 0.0};
  site.end_site = true;
  clip.joints = {root, arm, site};
  clip.frame_time_s = 1.0 / 120.0;
  clip.frame_count = frame_count;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> angle(-180.0, 180.0);
  for (std::size_t i = 0; i < frame_count * 9; ++i) clip.values.push_back(angle(rng));
  return clip;
}

}  // namespace tonus::test
