// The driver: checks, scale, per-frame solve, floor, continuity, report.
#include "tonus/host/reference/clip_reference.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <utility>

#include "floor.hpp"
#include "pose_solver.hpp"
#include "rig.hpp"
#include "rotations.hpp"
#include "tonus/host/balance/contacts.hpp"
#include "tonus/host/balance/convert.hpp"
#include "tonus/host/motion/bvh.hpp"

namespace tonus::reference {
namespace {

using detail::Bone;
using detail::Vec3;

std::string fixed(double v, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

bool finite_frame(const balance::MotionFrame& f) {
  for (const Vec3& p : f.p) {
    if (!sim::all_finite(p)) return false;
  }
  for (const balance::Quat& q : f.rotation) {
    if (!q.coeffs().allFinite() || q.norm() < 0.5) return false;
  }
  return true;
}

// Hip to ankle joint, mean over both legs and every frame.
double clip_leg_m(const balance::HumanMotion& motion) {
  double sum = 0.0;
  for (const balance::MotionFrame& f : motion.frames) {
    for (const Bone thigh : {Bone::LeftUpperLeg, Bone::RightUpperLeg}) {
      const std::size_t i = sim::index(thigh);
      sum += 0.5 * ((f.p[i + 1] - f.p[i]).norm() + (f.p[i + 2] - f.p[i + 1]).norm());
    }
  }
  return sum / static_cast<double>(motion.frames.size());
}

// Quaternions kept in the hemisphere of the previous frame's (the first
// frame's, of the rest configuration's identities).
void make_continuous(const sim::Model& m, std::vector<std::array<double, sim::kMaxQpos>>& qpos) {
  for (std::size_t f = 0; f < qpos.size(); ++f) detail::keep_hemisphere(m, qpos[f], f > 0 ? qpos[f - 1] : m.qpos0);
}

void report_clamps(ClipReference& r) {
  std::string msg = "clamped into the joint limits: " + std::to_string(r.frames_clamped) + " of " +
                    std::to_string(r.qpos.size()) + " frames";
  std::vector<std::pair<std::size_t, Bone>> worst;
  for (const sim::BoneInfo& b : sim::kBones) {
    if (r.clamped_frames[sim::index(b.bone)] > 0) worst.emplace_back(r.clamped_frames[sim::index(b.bone)], b.bone);
  }
  std::sort(worst.begin(), worst.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
  for (std::size_t k = 0; k < worst.size(); ++k) {
    msg += (k == 0 ? "; frames per joint: " : ", ") + std::string(sim::name(worst[k].second)) + " " +
           std::to_string(worst[k].first);
  }
  r.messages.push_back(msg);
}

void report_calibration(const detail::Calibration& c, ClipReference& r) {
  const std::array<std::string, 2> side = {"left", "right"};
  for (std::size_t k = 0; k < 2; ++k) {
    if (!c.elbow_axis[k]) r.messages.push_back("the " + side[k] + " elbow never bends: upper arm twist least");
    if (!c.knee_axis[k]) r.messages.push_back("the " + side[k] + " knee never bends: thigh twist least");
    if (!c.hand_axis[k]) r.messages.push_back("no " + side[k] + " hand roll found: hand twist least");
    if (!c.hand_dir[k]) r.messages.push_back("no steady " + side[k] + " hand direction: the tip landmark used");
    if (!c.foot_left[k]) r.messages.push_back("no " + side[k] + " foot roll found: foot kept level");
  }
  if (!c.head_left) r.messages.push_back("no head facing found: head twist least");
}

ClipReference retarget(const sim::Model& model, const balance::HumanMotion& motion) {
  ClipReference r;
  r.dt_s = motion.dt_s;
  r.first_frame = motion.first_frame;
  if (motion.frames.empty()) {
    r.error = "the motion has no frames";
    return r;
  }
  if (!std::isfinite(motion.dt_s) || motion.dt_s <= 0.0) {
    r.error = "the motion's frame time is not a positive number";
    return r;
  }
  for (std::size_t f = 0; f < motion.frames.size(); ++f) {
    if (!finite_frame(motion.frames[f])) {
      r.error = "frame " + std::to_string(f) + " has a landmark or rotation that is not finite";
      return r;
    }
  }
  detail::Rig rig;
  if (std::string e = detail::make_rig(model, rig); !e.empty()) {
    r.error = "not the humanoid model: " + e;
    return r;
  }
  r.nq = model.nq;
  const double clip_leg = clip_leg_m(motion);
  if (!(clip_leg > 0.05)) {
    r.error = "the clip's legs have no length (hip, knee and ankle joints nearly coincide)";
    return r;
  }
  r.scale = rig.leg_m / clip_leg;
  r.messages.push_back("leg length: clip " + fixed(clip_leg, 3) + " m, humanoid " + fixed(rig.leg_m, 3) +
                       " m; the root's path scaled by " + fixed(r.scale, 3));

  const balance::ContactTrack contacts = balance::detect_contacts(motion, balance::ContactOptions{});
  const double ground = motion.size() >= 3 ? contacts.ground_z_m : 0.0;
  const detail::Calibration cal = detail::calibrate(motion, contacts);
  report_calibration(cal, r);
  const detail::Neutral neutral = detail::measure_neutral(rig, cal, motion, contacts, r.messages);

  const auto root_target = [&](std::size_t f) {
    return Vec3(r.scale * (motion.frames[f].p[balance::index(balance::Landmark::MidHip)] - Vec3(0.0, 0.0, ground)));
  };
  detail::FrameResult frame;
  r.qpos.resize(motion.size());
  for (std::size_t f = 0; f < motion.size(); ++f) {
    detail::solve_frame(rig, cal, neutral, motion.frames[f], root_target(f), frame);
    r.qpos[f] = frame.qpos;
    bool any = false;
    for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
      if (frame.clamped[b]) ++r.clamped_frames[b];
      any = any || frame.clamped[b];
    }
    if (any) ++r.frames_clamped;
  }

  const detail::FloorFit floor = detail::fit_floor(model, r.qpos, contacts);
  const std::size_t z = static_cast<std::size_t>(rig.body(Bone::Hips).qpos_adr) + 2;
  for (auto& q : r.qpos) q[z] += floor.offset_m;
  r.ground_offset_m = floor.offset_m - r.scale * ground;
  r.messages.push_back(floor.samples > 0 ? "floor: the feet's lowest points in " + std::to_string(floor.samples) +
                                               " foot contacts put at z = 0 (median)"
                                         : "floor: no foot contacts found; the feet's lowest frames put at z = 0");
  make_continuous(model, r.qpos);
  report_clamps(r);
  return r;
}

}  // namespace

ClipReference clip_to_reference(const sim::Model& humanoid, const balance::HumanMotion& motion) {
  try {
    return retarget(humanoid, motion);
  } catch (const std::exception& e) {  // out of memory, in practice
    ClipReference r;
    r.error = std::string("retargeting failed: ") + e.what();
    return r;
  }
}

ClipReference clip_to_reference(const sim::Model& humanoid, const std::string& bvh_path) {
  return clip_to_reference(humanoid, bvh_path, balance::BalanceStageOptions{});
}

ClipReference clip_to_reference(const sim::Model& humanoid, const std::string& bvh_path,
                                const balance::BalanceStageOptions& balance) {
  ClipReference r;
  try {
    motion::ReadResult read = motion::read_bvh_file(bvh_path);
    if (!read.ok()) {
      r.error = bvh_path + (read.error->line > 0 ? ":" + std::to_string(read.error->line) : std::string()) + ": " +
                read.error->message;
      return r;
    }
    const balance::MapResult mapping = balance::map_skeleton(read.clip);
    if (!mapping.ok()) {
      r.error = bvh_path + ": " + mapping.error;
      return r;
    }
    const balance::Conversion conv = balance::convert_motion(read.clip, mapping, balance::ConvertOptions{});
    if (!conv.ok()) {
      r.error = bvh_path + ": " + conv.error;
      return r;
    }
    const balance::BalanceStageResult balanced = balance::balance_stage(conv.motion, balance);
    if (!balanced.ok()) {
      r.error = bvh_path + ": " + balanced.error;
      return r;
    }
    r = retarget(humanoid, balanced.motion);
    std::string balance_note;
    std::vector<std::string> notes;  // the reading's and the conversion's first
    for (const motion::Diagnostic& w : read.warnings) notes.push_back("bvh: " + w.message);
    notes.insert(notes.end(), conv.messages.begin(), conv.messages.end());
    if (balance.mode != balance::BalanceMode::off) {
      std::string mode(balance::to_string(balance.mode));
      if (balance.mode == balance::BalanceMode::online) {
        mode += ", look-ahead " + std::to_string(balanced.lookahead_frames) + " frames";
      }
      balance_note = "balance (" + mode + "): supported frames with the ZMP outside by more than 1 cm: " +
                     std::to_string(balanced.frames_outside_before) + " -> " +
                     std::to_string(balanced.frames_outside_after) + " of " +
                     std::to_string(balanced.supported_frames) + "; under the worst estimator of the family after (" +
                     std::to_string(static_cast<int>(balanced.worst_member_cutoff_hz)) + " Hz " +
                     (balanced.worst_member_full ? "full" : "particle") +
                     "): " + std::to_string(balanced.worst_member_outside_after) +
                     (balanced.balanced ? " (balanced)" : " (not balanced under every estimator)");
      notes.push_back(balance_note);
    }
    notes.insert(notes.end(), r.messages.begin(), r.messages.end());
    r.messages = std::move(notes);
    r.balance = std::move(balance_note);
  } catch (const std::exception& e) {
    r = ClipReference{};
    r.error = bvh_path + ": retargeting failed: " + e.what();
  }
  return r;
}

}  // namespace tonus::reference
