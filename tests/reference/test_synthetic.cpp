// A clip made here, in the humanoid's own T-pose, with closed-form answers:
// the right elbow bent 90 degrees forward, the left arm lowered 60 degrees.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "reference_checks.hpp"
#include "tonus/host/balance/skeleton_map.hpp"
#include "tonus/host/motion/bvh.hpp"

using namespace tonus;
using reference::ClipReference;
using sim::Bone;
using sim::Quat;

namespace {

// Y up, facing +Z, the left side on +X, centimetres, a T-pose at rest.
constexpr const char* kHierarchy = R"(HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT Chest
    {
      OFFSET 0 12 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT Neck
      {
        OFFSET 0 20 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        JOINT Head
        {
          OFFSET 0 8 0
          CHANNELS 3 Zrotation Xrotation Yrotation
          End Site
          {
            OFFSET 0 18 0
          }
        }
      }
      JOINT LeftShoulder
      {
        OFFSET 3 16 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        JOINT LeftUpperArm
        {
          OFFSET 15 0 0
          CHANNELS 3 Zrotation Xrotation Yrotation
          JOINT LeftLowerArm
          {
            OFFSET 28 0 0
            CHANNELS 3 Zrotation Xrotation Yrotation
            JOINT LeftHand
            {
              OFFSET 25 0 0
              CHANNELS 3 Zrotation Xrotation Yrotation
              End Site
              {
                OFFSET 18 0 0
              }
            }
          }
        }
      }
      JOINT RightShoulder
      {
        OFFSET -3 16 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        JOINT RightUpperArm
        {
          OFFSET -15 0 0
          CHANNELS 3 Zrotation Xrotation Yrotation
          JOINT RightLowerArm
          {
            OFFSET -28 0 0
            CHANNELS 3 Zrotation Xrotation Yrotation
            JOINT RightHand
            {
              OFFSET -25 0 0
              CHANNELS 3 Zrotation Xrotation Yrotation
              End Site
              {
                OFFSET -18 0 0
              }
            }
          }
        }
      }
    }
  }
  JOINT LeftUpperLeg
  {
    OFFSET 9 0 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT LeftLowerLeg
    {
      OFFSET 0 -42 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT LeftFoot
      {
        OFFSET 0 -40 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        JOINT LeftToes
        {
          OFFSET 0 -6 13
          CHANNELS 3 Zrotation Xrotation Yrotation
          End Site
          {
            OFFSET 0 0 6
          }
        }
      }
    }
  }
  JOINT RightUpperLeg
  {
    OFFSET -9 0 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT RightLowerLeg
    {
      OFFSET 0 -42 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT RightFoot
      {
        OFFSET 0 -40 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        JOINT RightToes
        {
          OFFSET 0 -6 13
          CHANNELS 3 Zrotation Xrotation Yrotation
          End Site
          {
            OFFSET 0 0 6
          }
        }
      }
    }
  }
}
)";

// Channel columns: Hips 0-5, then 3 per joint in file order (Spine 6, Chest 9,
// Neck 12, Head 15, LeftShoulder 18, LeftUpperArm 21, LeftLowerArm 24,
// LeftHand 27, RightShoulder 30, RightUpperArm 33, RightLowerArm 36, ...).
constexpr int kChannels = 6 + 3 * 20;
constexpr int kLeftUpperArmZ = 21;
constexpr int kRightLowerArmY = 36 + 2;

std::string frame_line(bool posed) {
  std::string line;
  for (int c = 0; c < kChannels; ++c) {
    double v = c == 1 ? 90.0 : 0.0;  // the hips 90 cm up
    if (posed && c == kLeftUpperArmZ) v = -60.0;
    if (posed && c == kRightLowerArmY) v = 90.0;
    if (c > 0) line.push_back(' ');
    line.append(std::to_string(v));
  }
  line.push_back('\n');
  return line;
}

Quat joint_quat(const sim::Model& m, const ClipReference& r, std::size_t frame, Bone b) {
  const auto a = static_cast<std::size_t>(m.bodies[sim::index(b)].qpos_adr);
  const auto& q = r.qpos[frame];
  return {q[a], q[a + 1], q[a + 2], q[a + 3]};
}

double hinge(const sim::Model& m, const ClipReference& r, std::size_t frame, Bone b) {
  return r.qpos[frame][static_cast<std::size_t>(m.bodies[sim::index(b)].qpos_adr)];
}

}  // namespace

TEST_CASE("reference: a T-pose clip with a bent right elbow and a lowered left arm gives the closed-form angles") {
  const std::string text = std::string(kHierarchy) + "MOTION\nFrames: 3\nFrame Time: 0.0333333\n" + frame_line(false) +
                           frame_line(true) + frame_line(true);
  const motion::ReadResult read = motion::parse_bvh(text);
  REQUIRE_MESSAGE(read.ok(), read.error->message);
  const balance::MapResult mapping = balance::map_skeleton(read.clip);
  REQUIRE_MESSAGE(mapping.ok(), mapping.error);
  const balance::Conversion conv = balance::convert_motion(read.clip, mapping, balance::ConvertOptions{});
  REQUIRE_MESSAGE(conv.ok(), conv.error);
  const sim::Model& m = reference::test::humanoid();
  const ClipReference r = reference::clip_to_reference(m, conv.motion);
  REQUIRE_MESSAGE(r.ok(), r.error);
  REQUIRE(r.qpos.size() == 3);
  CHECK(r.frames_clamped == 0);

  const Quat lowered(Eigen::AngleAxisd(-M_PI / 3.0, sim::Vec3::UnitX()));  // +Y (left) turned 60 degrees down
  for (std::size_t f = 0; f < 3; ++f) {
    CAPTURE(f);
    const bool posed = f > 0;
    // The pose asked for.
    CHECK(hinge(m, r, f, Bone::RightLowerArm) == doctest::Approx(posed ? M_PI / 2.0 : 0.0).epsilon(1e-9));
    CHECK(joint_quat(m, r, f, Bone::LeftUpperArm).angularDistance(posed ? lowered : Quat::Identity()) < 1e-9);
    // Everything else at rest: no twist, no bend the clip does not have.
    for (const sim::BoneInfo& b : sim::kBones) {
      if (b.bone == Bone::Hips || b.bone == Bone::LeftUpperArm || b.bone == Bone::RightLowerArm) continue;
      CAPTURE(b.name);
      const sim::Body& body = m.bodies[sim::index(b.bone)];
      if (body.joint == sim::JointType::hinge) {
        CHECK(std::abs(hinge(m, r, f, b.bone)) < 1e-9);
      } else {
        CHECK(joint_quat(m, r, f, b.bone).angularDistance(Quat::Identity()) < 1e-9);
      }
    }
    // The root upright, facing +X, over the origin, at the humanoid's own hip height (feet flat on z = 0).
    const auto& q = r.qpos[f];
    CHECK(Quat(q[3], q[4], q[5], q[6]).angularDistance(Quat::Identity()) < 1e-9);
    CHECK(std::abs(q[0]) < 1e-9);
    CHECK(std::abs(q[1]) < 1e-9);
    CHECK(q[2] == doctest::Approx(m.bodies[0].pos_in_parent.z()).epsilon(1e-9));
  }
  // The leg lengths set the scale: 82 cm hip to ankle against the humanoid's.
  const double humanoid_leg = m.bodies[sim::index(Bone::LeftLowerLeg)].pos_in_parent.norm() +
                              m.bodies[sim::index(Bone::LeftFoot)].pos_in_parent.norm();
  CHECK(r.scale == doctest::Approx(humanoid_leg / 0.82).epsilon(1e-9));
}
