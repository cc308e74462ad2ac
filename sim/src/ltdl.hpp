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

#include <cstdint>
#include <span>

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

// x <- L^-1 x (the second half, after scaling by D^-1).
void solve_l(std::span<const double> f, int nv, std::span<const int> parent, int first, std::span<double> x);

}  // namespace tonus::sim::ltdl
