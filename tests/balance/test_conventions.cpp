// Skeleton conventions recognised by their joint names (synthetic T-pose BVH
// clips written here, one per convention), the shape-based fallback for
// unknown names, and the refusal of skeletons that are not humanoids.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "balance_fixtures.hpp"
#include "tonus/host/balance/convert.hpp"
#include "tonus/host/motion/bvh.hpp"

using namespace tonus::balance;
namespace motion = tonus::motion;
using tonus::sim::Bone;

namespace {

// Joint names in HumanBodyBones order; "" for a joint the convention lacks
// (only the toes may be left out).
using Names = std::array<std::string, tonus::sim::kBoneCount>;

struct Rig {
  const char* convention;  // expected SkeletonMap::convention
  Names names;
  std::string root_above_hips;   // a joint above the hips (Biped's "Bip01"), or ""
  std::string extra_hand_child;  // a joint under the left hand, or ""
};

std::string name(const Names& n, Bone b) { return n[tonus::sim::index(b)]; }

// A T-pose humanoid in centimetres, Y up, facing +Z (left at +X), four frames.
std::string bvh(const Rig& rig) {
  const Names& n = rig.names;
  std::string text = "HIERARCHY\n";
  int channels = 0;
  int depth = 0;
  const auto pad = [&] { return std::string(static_cast<std::size_t>(depth) * 2, ' '); };
  const auto open = [&](const std::string& keyword, const std::string& joint, double x, double y, double z) {
    text += pad() + keyword + " " + joint + "\n" + pad() + "{\n";
    ++depth;
    text += pad() + "OFFSET " + std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) + "\n";
    if (depth == 1) {
      text += pad() + "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n";
      channels += 6;
    } else {
      text += pad() + "CHANNELS 3 Zrotation Xrotation Yrotation\n";
      channels += 3;
    }
  };
  const auto end_site = [&](double x, double y, double z) {
    text += pad() + "End Site\n" + pad() + "{\n" + pad() + "  OFFSET " + std::to_string(x) + " " + std::to_string(y) +
            " " + std::to_string(z) + "\n" + pad() + "}\n";
  };
  const auto close = [&] {
    --depth;
    text += pad() + "}\n";
  };
  const bool root_above = !rig.root_above_hips.empty();
  if (root_above) open("ROOT", rig.root_above_hips, 0, 0, 0);
  open(root_above ? "JOINT" : "ROOT", name(n, Bone::Hips), 0, 0, 0);
  open("JOINT", name(n, Bone::Spine), 0, 10, 0);
  open("JOINT", name(n, Bone::Chest), 0, 15, 0);
  open("JOINT", name(n, Bone::Neck), 0, 20, 0);
  open("JOINT", name(n, Bone::Head), 0, 10, 0);
  end_site(0, 18, 0);
  close();
  close();
  for (const double s : {1.0, -1.0}) {
    const bool left = s > 0;
    open("JOINT", name(n, left ? Bone::LeftShoulder : Bone::RightShoulder), 5 * s, 15, 0);
    open("JOINT", name(n, left ? Bone::LeftUpperArm : Bone::RightUpperArm), 12 * s, 0, 0);
    open("JOINT", name(n, left ? Bone::LeftLowerArm : Bone::RightLowerArm), 30 * s, 0, 0);
    open("JOINT", name(n, left ? Bone::LeftHand : Bone::RightHand), 25 * s, 0, 0);
    if (left && !rig.extra_hand_child.empty()) {
      open("JOINT", rig.extra_hand_child, 8 * s, 0, 0);
      end_site(10 * s, 0, 0);
      close();
    } else {
      end_site(18 * s, 0, 0);
    }
    close();
    close();
    close();
    close();
  }
  close();  // chest
  close();  // spine
  for (const double s : {1.0, -1.0}) {
    const bool left = s > 0;
    open("JOINT", name(n, left ? Bone::LeftUpperLeg : Bone::RightUpperLeg), 9 * s, -5, 0);
    open("JOINT", name(n, left ? Bone::LeftLowerLeg : Bone::RightLowerLeg), 0, -42, 0);
    open("JOINT", name(n, left ? Bone::LeftFoot : Bone::RightFoot), 0, -40, 0);
    const std::string toes = name(n, left ? Bone::LeftToes : Bone::RightToes);
    if (!toes.empty()) {
      open("JOINT", toes, 0, -6, 12);
      end_site(0, 0, 6);
      close();
    } else {
      end_site(0, -6, 18);
    }
    close();
    close();
    close();
  }
  close();  // hips
  if (root_above) close();
  // Four frames: standing, then a small sway of the root and the arms.
  text += "MOTION\nFrames: 4\nFrame Time: 0.0333333\n";
  for (int f = 0; f < 4; ++f) {
    for (int c = 0; c < channels; ++c) {
      double v = 0.0;
      if (c == 0) v = 0.5 * f;
      if (c == 1) v = 95.0;                   // the root's height
      if (c >= 6 && c % 3 == 0) v = 2.0 * f;  // a little Z rotation everywhere
      text += std::to_string(v) + (c + 1 < channels ? " " : "\n");
    }
  }
  return text;
}

// The names with the left side spelled `left` and the right `right` at each '*'.
Names sided(const std::array<std::string, 13>& one_sided, const std::string& left, const std::string& right) {
  const auto put = [](std::string s, const std::string& side) {
    if (const auto star = s.find('*'); star != std::string::npos) s.replace(star, 1, side);
    return s;
  };
  Names n;
  for (std::size_t i = 0; i < 5; ++i) n[i] = one_sided[i];
  for (std::size_t i = 0; i < 4; ++i) {
    n[tonus::sim::index(Bone::LeftShoulder) + i] = put(one_sided[5 + i], left);
    n[tonus::sim::index(Bone::RightShoulder) + i] = put(one_sided[5 + i], right);
    n[tonus::sim::index(Bone::LeftUpperLeg) + i] = put(one_sided[9 + i], left);
    n[tonus::sim::index(Bone::RightUpperLeg) + i] = put(one_sided[9 + i], right);
  }
  return n;
}

std::vector<Rig> rigs() {
  std::vector<Rig> r;
  const auto prefixed = [](Names n, const std::string& prefix) {
    for (std::string& s : n) {
      if (!s.empty()) s.insert(0, prefix);
    }
    return n;
  };
  const Names humanik = sided({"Hips", "Spine", "Spine1", "Neck", "Head", "*Shoulder", "*Arm", "*ForeArm", "*Hand",
                               "*UpLeg", "*Leg", "*Foot", "*ToeBase"},
                              "Left", "Right");
  r.push_back({"Mixamo", prefixed(humanik, "mixamorig:"), "", ""});
  r.push_back({"Mixamo", prefixed(humanik, "mixamorig1:"), "", ""});
  r.push_back({"MotionBuilder HumanIK", humanik, "", ""});
  r.push_back({"MotionBuilder HumanIK", prefixed(humanik, "Character1_"), "", ""});
  Names neuron = humanik;
  neuron[tonus::sim::index(Bone::Chest)] = "Spine2";
  neuron[tonus::sim::index(Bone::LeftToes)] = neuron[tonus::sim::index(Bone::RightToes)] = "";
  r.push_back({"Perception Neuron", neuron, "", "LeftInHandIndex"});
  const Names biped = sided({"Bip01 Pelvis", "Bip01 Spine", "Bip01 Spine1", "Bip01 Neck", "Bip01 Head",
                             "Bip01 * Clavicle", "Bip01 * UpperArm", "Bip01 * Forearm", "Bip01 * Hand", "Bip01 * Thigh",
                             "Bip01 * Calf", "Bip01 * Foot", "Bip01 * Toe0"},
                            "L", "R");
  r.push_back({"3dsMax Biped", biped, "Bip01", ""});
  Names biped_ = biped;
  for (std::string& s : biped_) std::replace(s.begin(), s.end(), ' ', '_');
  r.push_back({"3dsMax Biped", biped_, "Bip01", ""});
  r.push_back({"Daz",
               sided({"hip", "abdomen", "chest", "neck", "head", "*Collar", "*Shldr", "*ForeArm", "*Hand", "*Thigh",
                      "*Shin", "*Foot", "*Toe"},
                     "l", "r"),
               "", ""});
  r.push_back({"Daz",
               sided({"hip", "abdomenLower", "chestUpper", "neckLower", "head", "*Collar", "*ShldrBend", "*ForearmBend",
                      "*Hand", "*ThighBend", "*Shin", "*Foot", "*Toe"},
                     "l", "r"),
               "", ""});
  r.push_back({"Unity HumanBodyBones",
               sided({"Hips", "Spine", "Chest", "Neck", "Head", "*Shoulder", "*UpperArm", "*LowerArm", "*Hand",
                      "*UpperLeg", "*LowerLeg", "*Foot", "*Toes"},
                     "Left", "Right"),
               "", ""});
  r.push_back({"VRM (J_Bip)",
               sided({"J_Bip_C_Hips", "J_Bip_C_Spine", "J_Bip_C_Chest", "J_Bip_C_Neck", "J_Bip_C_Head",
                      "J_Bip_*_Shoulder", "J_Bip_*_UpperArm", "J_Bip_*_LowerArm", "J_Bip_*_Hand", "J_Bip_*_UpperLeg",
                      "J_Bip_*_LowerLeg", "J_Bip_*_Foot", "J_Bip_*_ToeBase"},
                     "L", "R"),
               "", ""});
  r.push_back(
      {"Blender Rigify",
       sided({"DEF-spine", "DEF-spine.001", "DEF-spine.002", "DEF-spine.004", "DEF-spine.006", "DEF-shoulder.*",
              "DEF-upper_arm.*", "DEF-forearm.*", "DEF-hand.*", "DEF-thigh.*", "DEF-shin.*", "DEF-foot.*", "DEF-toe.*"},
             "L", "R"),
       "", ""});
  r.push_back({"Rokoko",
               sided({"Hips", "Spine", "Spine2", "Neck", "Head", "*Shoulder", "*Arm", "*ForeArm", "*Hand", "*Thigh",
                      "*Shin", "*Foot", "*Toe"},
                     "Left", "Right"),
               "", ""});
  r.push_back({"Xsens MVN",
               sided({"Pelvis", "L5", "T8", "Neck", "Head", "*Shoulder", "*UpperArm", "*ForeArm", "*Hand", "*UpperLeg",
                      "*LowerLeg", "*Foot", "*Toe"},
                     "Left", "Right"),
               "", ""});
  r.push_back({"OptiTrack Motive",
               prefixed(sided({"Hip", "Ab", "Chest", "Neck", "Head", "*Shoulder", "*UArm", "*FArm", "*Hand", "*Thigh",
                               "*Shin", "*Foot", "*Toe"},
                              "L", "R"),
                        "Skeleton_"),
               "", ""});
  r.push_back({"Bandai Namco Research Motiondataset",
               sided({"Hips", "Spine", "Chest", "Neck", "Head", "Shoulder_*", "UpperArm_*", "LowerArm_*", "Hand_*",
                      "UpperLeg_*", "LowerLeg_*", "Foot_*", "Toes_*"},
                     "L", "R"),
               "", ""});
  Names made_up;
  for (std::size_t i = 0; i < made_up.size(); ++i) {
    made_up[i] = std::to_string(i);
    made_up[i].insert(made_up[i].begin(), 'j');
  }
  r.push_back({"topology", made_up, "", ""});
  return r;
}

std::string joint_for(const motion::Clip& clip, const MapResult& m, Bone b) {
  const int j = m.map.joint[tonus::sim::index(b)];
  return j < 0 ? "(none)" : clip.joints[static_cast<std::size_t>(j)].name;
}

}  // namespace

TEST_CASE("conventions: each convention's names are recognised, reported, mapped and converted") {
  for (const Rig& rig : rigs()) {
    const std::string text = bvh(rig);
    INFO(rig.convention, " (hips '", name(rig.names, Bone::Hips), "')");
    const motion::ReadResult read = motion::parse_bvh(text);
    REQUIRE_MESSAGE(read.ok(), text);
    const MapResult m = map_skeleton(read.clip);
    REQUIRE_MESSAGE(m.ok(), m.error);
    CHECK(m.map.convention == rig.convention);
    for (const Bone b : {Bone::Hips, Bone::LeftUpperLeg, Bone::RightLowerArm, Bone::Head, Bone::LeftHand,
                         Bone::RightFoot, Bone::Chest}) {
      CHECK_MESSAGE(joint_for(read.clip, m, b) == name(rig.names, b), tonus::sim::name(b));
    }
    const Conversion conv = convert_motion(read.clip, m, {});
    REQUIRE_MESSAGE(conv.ok(), conv.error);
    CHECK(conv.geometry.metres_per_unit == doctest::Approx(0.01));
    CHECK(conv.motion.size() == 4);
  }
}

TEST_CASE("conventions: unknown names fall back to the shape, and say so") {
  Rig rig = rigs().back();
  REQUIRE(std::string(rig.convention) == "topology");
  // Left and right come from the rest pose, not from the file order: swap the sides' names.
  for (std::size_t i = 0; i < 4; ++i) {
    std::swap(rig.names[tonus::sim::index(Bone::LeftUpperLeg) + i],
              rig.names[tonus::sim::index(Bone::RightUpperLeg) + i]);
  }
  const motion::ReadResult read = motion::parse_bvh(bvh(rig));
  REQUIRE(read.ok());
  const MapResult m = map_skeleton(read.clip);
  REQUIRE_MESSAGE(m.ok(), m.error);
  CHECK(m.map.convention == "topology");
  // The file's first leg (at +X, the character's left) is the left leg whatever it is called.
  CHECK(joint_for(read.clip, m, Bone::LeftUpperLeg) == name(rig.names, Bone::LeftUpperLeg));
  CHECK(read.clip.joints[static_cast<std::size_t>(m.map.joint[tonus::sim::index(Bone::LeftUpperLeg)])].offset.x() > 0);
  CHECK(joint_for(read.clip, m, Bone::Spine) == "j1");
  CHECK(joint_for(read.clip, m, Bone::Neck) == "j3");
  CHECK(joint_for(read.clip, m, Bone::LeftShoulder) == "j5");
  bool said = false;
  for (const std::string& n : m.notes) said = said || n.find("topology") != std::string::npos;
  CHECK(said);
  const Conversion conv = convert_motion(read.clip, m, {});
  REQUIRE_MESSAGE(conv.ok(), conv.error);
  bool told = false;
  for (const std::string& n : conv.messages) told = told || n.find("topology") != std::string::npos;
  CHECK(told);
}

TEST_CASE("conventions: the CMU walk with its names erased maps by its shape to the same limbs") {
  const test::Loaded named = test::load(test::bundled_clip("cmu_02_walk.bvh"));
  motion::Clip erased = named.clip;
  for (std::size_t j = 0; j < erased.joints.size(); ++j) {
    if (erased.joints[j].end_site) continue;
    erased.joints[j].name = std::to_string(j);
    erased.joints[j].name.insert(erased.joints[j].name.begin(), 'j');
  }
  const MapResult m = map_skeleton(erased);
  REQUIRE_MESSAGE(m.ok(), m.error);
  CHECK(m.map.convention == "topology");
  for (std::size_t b = 0; b < tonus::sim::kBoneCount; ++b) {
    const Bone bone = tonus::sim::kBones[b].bone;
    // CMU has two lower-spine and two neck joints; the shape cannot tell which one the names pick.
    if (bone == Bone::Neck || bone == Bone::Spine) continue;
    CHECK_MESSAGE(m.map.joint[b] == named.mapping.map.joint[b], tonus::sim::name(bone));
  }
  CHECK(convert_motion(erased, m, {}).ok());
}

TEST_CASE("conventions: a skeleton that is no humanoid is refused with the reason") {
  const char* chain =
      "HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation "
      "Xrotation Yrotation\n JOINT b\n {\n  OFFSET 0 10 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "  JOINT c\n  {\n   OFFSET 0 10 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n   End Site\n"
      "   {\n    OFFSET 0 10 0\n   }\n  }\n }\n}\nMOTION\nFrames: 2\nFrame Time: 0.04\n"
      "0 0 0 0 0 0 0 0 0 0 0 0\n0 0 0 0 0 0 0 0 0 0 0 0\n";
  const motion::ReadResult read = motion::parse_bvh(chain);
  REQUIRE(read.ok());
  const MapResult m = map_skeleton(read.clip);
  CHECK_FALSE(m.ok());
  CHECK(m.error.find("no joint for Hips") != std::string::npos);
  CHECK(m.error.find("shape") != std::string::npos);
  CHECK(m.error.find("mapping file") != std::string::npos);
  // A mapping file still rescues a known-names skeleton with one odd name; the shape is not consulted then.
  Rig rig = rigs()[2];  // MotionBuilder HumanIK
  rig.names[tonus::sim::index(Bone::LeftUpperLeg)] = "odd_thigh";
  const motion::ReadResult odd = motion::parse_bvh(bvh(rig));
  REQUIRE(odd.ok());
  const MapResult refused = map_skeleton(odd.clip);
  CHECK_FALSE(refused.ok());
  CHECK(refused.error.find("LeftUpperLeg") != std::string::npos);
  CHECK(map_skeleton(odd.clip, "LeftUpperLeg = odd_thigh").ok());
}
