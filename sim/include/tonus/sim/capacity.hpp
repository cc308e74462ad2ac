// Fixed capacities of the physics core, chosen for one humanoid (21 bodies,
// 54 degrees of freedom) and a viewers' gift spam: a hundred balls or cubes
// on and around it. Every array grows linearly with these (the solver keeps
// no matrix of row pairs), so sizeof(Data) is about 1.4 MB.
// Everything in Data is sized from these at compile time; builders and
// add_object() check them and refuse what does not fit.
#pragma once

#include <cstddef>

namespace tonus::sim {

inline constexpr std::size_t kMaxBodies = 32;      // articulated bodies, root included
inline constexpr std::size_t kMaxDofs = 64;        // generalized velocities of the articulation
inline constexpr std::size_t kMaxQpos = 88;        // generalized positions (quaternions take 4)
inline constexpr std::size_t kMaxGeoms = 48;       // collision shapes on the articulation
inline constexpr std::size_t kMaxObjects = 128;    // free virtual objects (balls, cubes)
inline constexpr std::size_t kMaxContacts = 1024;  // contact points per step (past it the least important go)
inline constexpr std::size_t kMaxJointRows = 96;   // joint rows per step: active limits and torque-limited drives
inline constexpr std::size_t kMaxRows = 3 * kMaxContacts + kMaxJointRows;  // constraint rows
// Rows that act on the articulation keep their (whitened) Jacobian on the dofs
// of their path to the root, packed; this pool holds all of them in a step
// (a foot's row has 16 entries: room for about a thousand such rows).
inline constexpr std::size_t kRowJacobianPool = 16384;
inline constexpr std::size_t kNameLength = 32;  // body names, NUL included

static_assert(kMaxDofs >= 6 + 3 * (kMaxBodies - 1) / 2, "room for a humanoid of ball joints");
static_assert(kMaxDofs <= 64, "a row's dofs are a 64-bit mask");
static_assert(kMaxDofs <= 256, "a packed Jacobian entry names its dof in one byte");
// The solver's subspace step solves the rows an island holds active as one
// dense system when sweeps alone are slow; islands with more active rows
// than this keep sweeping (the scratch is fixed: 96^2 doubles).
inline constexpr std::size_t kSubspaceRows = 96;
// Contacts leave this much of the pool to joint rows (limits, saturated drives: a
// humanoid's paths are at most 27 dofs long).
inline constexpr std::size_t kJointRowPoolReserve = kMaxJointRows * 28;
static_assert(kRowJacobianPool > 2 * kJointRowPoolReserve, "the pool is mostly for contacts");
static_assert(kMaxContacts <= 65535, "contacts are indexed with 16 bits");
// Every ball joint (3 dofs) and the free root take one position more than velocities.
static_assert(kMaxQpos >= kMaxDofs + kMaxDofs / 3 + 1, "room for the quaternions");

}  // namespace tonus::sim
