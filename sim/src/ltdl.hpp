// Sparse LTDL factorisation of a joint-space inertia matrix (Featherstone,
// RBDA section 6.5): H = L^T D L where L has the tree's sparsity (L[k][i] != 0
// only for dofs i on the path from k to the root), so factoring costs the sum
// of squared path lengths instead of n^3 / 3. Private to sim/.
//
// Matrices are nv x nv, row-major with stride nv, lower triangle used; the
// factor is written in place (D on the diagonal, L below). `parent` gives each
// dof's predecessor (-1 at the top); dofs below `first` are excluded (a fixed
// or kinematic root's dofs are prescribed, not solved for).
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "tonus/sim/capacity.hpp"

namespace tonus::sim::ltdl {

// Returns false if a pivot is not positive (the matrix is not positive definite).
bool factor(std::span<double> h, int nv, std::span<const int> parent, int first);

// x <- H^-1 x, using the factor.
void solve(std::span<const double> f, int nv, std::span<const int> parent, int first, std::span<double> x);

// x <- L^-T x (the first half of a solve).
void solve_lt(std::span<const double> f, int nv, std::span<const int> parent, int first, std::span<double> x);

// x <- L^-T x where x is zero off `support`, a set of dofs closed under
// ancestors (a row's paths to the root): touches those dofs only.
void solve_lt_on(std::span<const double> f, int nv, std::span<const int> parent, int first, std::uint64_t support,
                 std::span<double> x);

// L restricted to a chain of dofs (one body's path to the root, where each
// dof's parent is the one before it), copied dense so that the L^-T solves of
// the many rows on one body run over contiguous memory instead of walking
// the parents. The arithmetic and its order are solve_lt_on's.
struct PathFactor {
  std::uint64_t support = 0;  // the chain gathered, 0 for none
  int begin = 0;              // its first active dof's place in dofs
  int size = 0;
  // Filled by gather_path (left uninitialised: 32 KB a step for nothing).
  std::array<std::uint8_t, kMaxDofs> dofs;
  std::array<double, kMaxDofs * kMaxDofs> l;  // L[dofs[j]][dofs[i]] at j * kMaxDofs + i, i < j
};

// Gathers `support`'s L into p. False (and p unset) when it is not a chain.
bool gather_path(std::span<const double> f, int nv, std::span<const int> parent, int first, std::uint64_t support,
                 PathFactor& p);

// solve_lt_on over p's chain: x <- L^-T x, x zero off the chain.
void solve_lt_path(const PathFactor& p, std::span<double> x);

// x <- L^-1 x (the second half, after scaling by D^-1).
void solve_l(std::span<const double> f, int nv, std::span<const int> parent, int first, std::span<double> x);

}  // namespace tonus::sim::ltdl
