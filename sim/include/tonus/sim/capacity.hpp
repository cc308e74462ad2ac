// Fixed capacities of the physics core, chosen for one humanoid (21 bodies,
// 54 degrees of freedom) plus a handful of virtual objects, with headroom.
// Everything in Data is sized from these at compile time; builders and
// add_object() check them and refuse what does not fit.
#pragma once

#include <cstddef>

namespace tonus::sim {

inline constexpr std::size_t kMaxBodies = 32;     // articulated bodies, root included
inline constexpr std::size_t kMaxDofs = 64;       // generalized velocities of the articulation
inline constexpr std::size_t kMaxQpos = 88;       // generalized positions (quaternions take 4)
inline constexpr std::size_t kMaxGeoms = 48;      // collision shapes on the articulation
inline constexpr std::size_t kMaxObjects = 16;    // free virtual objects (balls, cubes)
inline constexpr std::size_t kMaxContacts = 64;   // contact points per step
inline constexpr std::size_t kMaxJointRows = 96;  // joint rows per step: active limits and torque-limited drives
inline constexpr std::size_t kMaxRows = 3 * kMaxContacts + kMaxJointRows;  // constraint rows
inline constexpr std::size_t kNameLength = 32;                             // body names, NUL included

static_assert(kMaxDofs >= 6 + 3 * (kMaxBodies - 1) / 2, "room for a humanoid of ball joints");
// Every ball joint (3 dofs) and the free root take one position more than velocities.
static_assert(kMaxQpos >= kMaxDofs + kMaxDofs / 3 + 1, "room for the quaternions");

}  // namespace tonus::sim
