// What the streamed-body code (BodyRetarget, BodyBalance) shares: a bone's
// parent in HumanBodyBones order, and the checks a sender's quaternion must pass.
#pragma once

#include <cmath>
#include <cstddef>

#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/math.hpp"

namespace tonus::reference::detail {

inline std::size_t parent_of(std::size_t i) { return sim::index(*sim::kBones[i].parent); }

inline bool finite(const sim::Quat& q) { return std::isfinite(q.w()) && sim::all_finite(q.vec()); }

// Finite and within `tolerance` of unit norm (BodyRetargetOptions::unit_tolerance).
inline bool usable(const sim::Quat& q, double tolerance) { return finite(q) && std::abs(q.norm() - 1.0) <= tolerance; }

}  // namespace tonus::reference::detail
