// What the streamed-body code (BodyRetarget, BodyBalance) shares: a bone's
// parent in HumanBodyBones order (and its nearest present one), and the checks a sender's quaternion must pass.
#pragma once

#include <cmath>
#include <cstddef>

#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/math.hpp"

namespace tonus::reference::detail {

inline std::size_t parent_of(std::size_t i) { return sim::index(*sim::kBones[i].parent); }

// A sender's bone's parent: its nearest ancestor in `present` (Hips, bone 0, counts as present).
template <class Present>
std::size_t present_parent(const Present& present, std::size_t i) {
  std::size_t p = parent_of(i);
  while (p != 0 && !present[p]) p = parent_of(p);
  return p;
}

inline bool finite(const sim::Quat& q) { return std::isfinite(q.w()) && sim::all_finite(q.vec()); }

// Finite and within `tolerance` of unit norm (BodyRetargetOptions::unit_tolerance).
inline bool usable(const sim::Quat& q, double tolerance) { return finite(q) && std::abs(q.norm() - 1.0) <= tolerance; }

}  // namespace tonus::reference::detail
