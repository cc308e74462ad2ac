// BVH text: never crash; an error names a line; an accepted clip is
// well-formed, poses its first and last frames, its joints' rotations
// survive quaternion -> Euler -> quaternion, and it writes back to a text
// that reads to a clip writing the very same text.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fuzz_check.hpp"
#include "tonus/host/motion/bvh.hpp"
#include "tonus/host/motion/euler.hpp"
#include "tonus/host/motion/kinematics.hpp"

using namespace tonus::motion;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const ReadResult r = parse_bvh(text);
  if (!r.ok()) {
    TONUS_FUZZ_CHECK(r.error->line >= 1);
    TONUS_FUZZ_CHECK(!r.error->message.empty());
    return 0;
  }
  const Clip& clip = r.clip;
  TONUS_FUZZ_CHECK(!check_clip(clip).has_value());
  std::vector<JointPose> poses;
  TONUS_FUZZ_CHECK(forward_kinematics(clip, 0, poses));
  TONUS_FUZZ_CHECK(forward_kinematics(clip, clip.frame_count - 1, poses));
  for (std::size_t j = 0; j < clip.joints.size(); ++j) {
    const std::optional<EulerOrder> order = rotation_order(clip.joints[j]);
    if (!order) continue;
    const Eigen::Quaterniond q = poses[j].local_rotation;
    const Eigen::Quaterniond back = quaternion_from_euler(*order, euler_from_quaternion(q, *order));
    TONUS_FUZZ_CHECK(back.angularDistance(q) < 1e-9);
  }
  const std::string written = write_bvh(clip);
  TONUS_FUZZ_CHECK(!written.empty());
  const ReadResult again = parse_bvh(written);
  TONUS_FUZZ_CHECK(again.ok());
  TONUS_FUZZ_CHECK(write_bvh(again.clip) == written);
  return 0;
}
