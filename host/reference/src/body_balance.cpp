#include "tonus/host/reference/body_balance.hpp"

#include <cmath>
#include <exception>
#include <utility>

#include "stream_checks.hpp"

namespace tonus::reference {
namespace {

using sim::Bone;
using sim::Quat;
using sim::Vec3;
constexpr std::size_t kN = sim::kBoneCount;

// As BodyRetarget's default: a quaternion further than this from unit is refused.
bool usable(const Quat& q) { return detail::usable(q, BodyRetargetOptions{}.unit_tolerance); }

double bone_length(const SourceSkeleton& s, Bone b) { return s.offset[sim::index(b)].norm(); }

}  // namespace

BodyBalance::Created BodyBalance::create(const SourceSkeleton& skeleton, const balance::OnlineOptions& options) {
  Created c;
  for (const Bone b : {Bone::LeftUpperLeg, Bone::LeftLowerLeg, Bone::LeftFoot, Bone::RightUpperLeg, Bone::RightLowerLeg,
                       Bone::RightFoot, Bone::LeftLowerArm, Bone::LeftHand, Bone::RightLowerArm, Bone::RightHand}) {
    if (!skeleton.present[sim::index(b)]) {
      c.error = std::string("the skeleton has no ") + std::string(sim::name(b));
      return c;
    }
  }
  for (std::size_t i = 0; i < kN; ++i) {
    if (skeleton.present[i] && !sim::all_finite(skeleton.offset[i])) {
      c.error = std::string("the skeleton's rest offset of ") + std::string(sim::kBones[i].name) + " is not finite";
      return c;
    }
  }
  const auto mean_length = [&](Bone l, Bone r) { return 0.5 * (bone_length(skeleton, l) + bone_length(skeleton, r)); };
  const double thigh = mean_length(Bone::LeftLowerLeg, Bone::RightLowerLeg);  // hip to knee
  const double shank = mean_length(Bone::LeftFoot, Bone::RightFoot);          // knee to ankle
  const double forearm = mean_length(Bone::LeftHand, Bone::RightHand);        // elbow to wrist
  if (!(thigh > 0.05 && shank > 0.05 && forearm > 0.02) || thigh + shank > 3.0) {
    c.error = "the skeleton's legs or forearms have no human length";
    return c;
  }
  try {
    balance::OnlineBalance::Created f = balance::OnlineBalance::create(options);
    if (!f) {
      c.error = "online balance filter: " + f.error;
      return c;
    }
    c.balance.emplace(
        BodyBalance(skeleton, balance::geometry_from_lengths(thigh, shank, forearm), std::move(*f.filter)));
  } catch (const std::exception& e) {  // out of memory, in practice
    c.error = std::string("online balance filter: ") + e.what();
  }
  return c;
}

BodyBalance::BodyBalance(const SourceSkeleton& skeleton, const balance::SkeletonGeometry& geometry,
                         balance::OnlineBalance filter)
    : skeleton_(skeleton), geometry_(geometry), filter_(std::move(filter)) {
  parent_.fill(-1);
  for (std::size_t i = 1; i < kN; ++i) parent_[i] = static_cast<int>(detail::present_parent(skeleton_.present, i));
  skeleton_.present[0] = true;
  // Until a value arrives: the rest.
  last_.present = skeleton_.present;
  last_.local = skeleton_.rest_rotation;
  last_.root_present = true;
  last_.root_position = skeleton_.offset[0];
  last_.root_rotation = skeleton_.rest_rotation[0];
  held_.resize(filter_.lookahead_frames() + 1);
}

balance::MotionFrame BodyBalance::landmarks(const BodySample& s) const {
  balance::MotionFrame f;
  f.rotation.fill(Quat::Identity());
  for (auto& p : f.p) p.setZero();
  f.p[0] = s.root_position;
  f.rotation[0] = s.root_rotation;
  for (std::size_t i = 1; i < kN; ++i) {
    if (!skeleton_.present[i]) continue;
    const auto p = static_cast<std::size_t>(parent_[i]);
    f.rotation[i] = (f.rotation[p] * s.local[i]).normalized();
    f.p[i] = f.p[p] + f.rotation[p] * skeleton_.offset[i];
  }
  balance::landmarks_from_bones(geometry_, skeleton_.present, f);
  return f;
}

bool BodyBalance::push(const BodySample& in, BodySample& out, balance::OnlineFrame* frame) {
  // Merge into the last valid values: what is absent or refused stays.
  bool refused = false;
  for (std::size_t i = 1; i < kN; ++i) {
    if (!skeleton_.present[i] || !in.present[i]) continue;
    if (usable(in.local[i])) {
      last_.local[i] = in.local[i].normalized();
    } else {
      refused = true;
    }
  }
  if (in.root_present) {
    if (sim::all_finite(in.root_position) && in.root_position.norm() <= 1e3) {
      last_.root_position = in.root_position;
    } else {
      refused = true;
    }
    if (usable(in.root_rotation)) {
      last_.root_rotation = in.root_rotation.normalized();
    } else {
      refused = true;
    }
  }
  if (refused) ++invalid_;
  held_[pushed_ % held_.size()] = last_;
  ++pushed_;
  if (!filter_.push(landmarks(last_), scratch_)) return false;
  return take(scratch_, out, frame);
}

bool BodyBalance::flush(BodySample& out, balance::OnlineFrame* frame) {
  if (!filter_.flush(scratch_)) return false;
  return take(scratch_, out, frame);
}

// The corrected frame back to local rotations and the root pose. Bones the
// filter did not turn come back as they went in, to rounding.
bool BodyBalance::take(const balance::OnlineFrame& f, BodySample& out, balance::OnlineFrame* info) {
  out = held_[f.index % held_.size()];
  const balance::MotionFrame& c = f.corrected;
  out.root_present = true;
  out.root_position = c.p[0];
  out.root_rotation = c.rotation[0].normalized();
  for (std::size_t i = 1; i < kN; ++i) {
    if (!skeleton_.present[i]) continue;
    const auto p = static_cast<std::size_t>(parent_[i]);
    const Quat local = (c.rotation[p].conjugate() * c.rotation[i]).normalized();
    if (usable(local)) out.local[i] = local;
  }
  if (!sim::all_finite(out.root_position)) out = held_[f.index % held_.size()];  // not expected: the input instead
  if (info != nullptr) *info = f;
  return true;
}

}  // namespace tonus::reference
