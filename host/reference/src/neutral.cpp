// The clip's neutral: its T-pose frame for the pelvis and shoulders, its
// flat-standing frames for the feet and toes.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "pose_solver.hpp"

namespace tonus::reference::detail {
namespace {

constexpr Bone kFeet[2] = {Bone::LeftFoot, Bone::RightFoot};

bool flat(const balance::ContactTrack& contacts, std::size_t t, std::size_t k) {
  return t < contacts.frames.size() && contacts.frames[t][k].heel && contacts.frames[t][k].ball;
}

std::string degrees(double rad) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", rad * 180.0 / M_PI);
  return buf;
}

}  // namespace

Neutral measure_neutral(const Rig& rig, const Calibration& cal, const balance::HumanMotion& motion,
                        const balance::ContactTrack& contacts, std::vector<std::string>& notes) {
  Neutral n;
  FrameResult scratch;
  if (motion.first_frame > 0 && !motion.frames.empty()) {
    solve_frame(rig, cal, Neutral{}, motion.frames[0], Vec3::Zero(), scratch, &n);
    notes.push_back("frame 0 is a T-pose: the pelvis's and shoulders' neutral taken from it");
  }
  // Feet: the clip's ankle-to-ball line, foot flat, against the humanoid's at rest.
  for (std::size_t k = 0; k < 2; ++k) {
    if (!cal.flat_foot_pitch_rad[k]) continue;
    const Vec3 rest = rig.rest_world[sim::index(kFeet[k])] * rig.dir[sim::index(kFeet[k])];
    n.foot_pitch_rad[k] = *cal.flat_foot_pitch_rad[k] - std::asin(std::clamp(-rest.z(), -1.0, 1.0));
  }
  // Toes: their matched angle where the (levelled) foot stands flat is their rest.
  std::array<double, 2> sum{};
  std::array<std::size_t, 2> count{};
  for (std::size_t t = motion.first_frame; t < motion.size(); ++t) {
    if (!flat(contacts, t, 0) && !flat(contacts, t, 1)) continue;
    solve_frame(rig, cal, n, motion.frames[t], Vec3::Zero(), scratch);
    for (std::size_t k = 0; k < 2; ++k) {
      if (!flat(contacts, t, k)) continue;
      sum[k] += scratch.toe_matched_rad[k];
      ++count[k];
    }
  }
  for (std::size_t k = 0; k < 2; ++k) {
    if (count[k] > 0) n.toe_rad[k] = sum[k] / static_cast<double>(count[k]);
  }
  if (count[0] + count[1] > 0) {
    notes.push_back("feet levelled where the clip's stand flat: toe-up " + degrees(n.foot_pitch_rad[0]) + " / " +
                    degrees(n.foot_pitch_rad[1]) + " deg (left / right), toes " + degrees(-n.toe_rad[0]) + " / " +
                    degrees(-n.toe_rad[1]) + " deg");
  } else {
    notes.push_back("no flat-standing foot in the clip: feet and toes matched as they are");
  }
  return n;
}

}  // namespace tonus::reference::detail
