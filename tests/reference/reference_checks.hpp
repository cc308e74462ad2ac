// Checks of retargeted clips that do not use the retargeting code: the
// humanoid's own forward kinematics (sim) against the clip's landmarks
// (balance), and the joint ranges measured by a swing-twist decomposition
// written here.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "tonus/host/balance/convert.hpp"
#include "tonus/host/reference/clip_reference.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::reference::test {

inline std::string shared_clip(const std::string& name) { return std::string(TONUS_SHARED_DATA_DIR) + "/bvh/" + name; }
inline std::string bundled_clip(const std::string& name) {
  return std::string(TONUS_SOURCE_DIR) + "/tests/data/" + name;
}

// The default humanoid (1.70 m), built once.
const sim::Model& humanoid();

// Reads, maps and converts a clip; fails the test on any error.
balance::Conversion load(const std::string& path);

struct Spread {
  std::size_t n = 0;
  double median = 0.0, p95 = 0.0, max = 0.0;
};
Spread spread(std::vector<double> v);

// Segments compared: upper arm, forearm, thigh, shank (both sides), spine, neck.
inline constexpr std::size_t kSegmentKinds = 6;
inline constexpr std::array<const char*, kSegmentKinds> kSegmentNames = {"upper arm", "forearm", "thigh",
                                                                         "shank",     "spine",   "neck"};

struct Figures {
  std::array<Spread, kSegmentKinds> segment_deg;  // angle between the humanoid's and the clip's segment
  Spread all_deg;
  Spread contact_foot_z_m;  // |lowest point of a foot| in the clip's foot-contact frames
  double max_quat_norm_error = 0.0;
  std::size_t sign_flips = 0;  // consecutive quaternions of a joint with a negative dot product
  double max_step_deg = 0.0;   // largest change of a ball joint's rotation between two frames
  std::size_t limit_violations = 0;
  std::string worst_violation;
  double root_path_error_m = 0.0;  // humanoid mid-hip vs the clip's, scaled (horizontal)
};

// Evaluates every frame from motion.first_frame on.
Figures evaluate(const sim::Model& model, const balance::HumanMotion& motion, const ClipReference& ref);

// Swing (angle between t and q t) and twist (about t) of a ball joint's quaternion.
struct SwingTwist {
  double swing = 0.0, twist = 0.0;
};
SwingTwist swing_twist(const sim::Quat& q, const sim::Vec3& t);

}  // namespace tonus::reference::test
