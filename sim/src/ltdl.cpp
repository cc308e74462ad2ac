#include "ltdl.hpp"

#include <array>
#include <bit>
#include <cstddef>

namespace tonus::sim::ltdl {
namespace {
inline std::size_t at(int r, int c, int nv) {
  return static_cast<std::size_t>(r) * static_cast<std::size_t>(nv) + static_cast<std::size_t>(c);
}
inline int up(std::span<const int> parent, int k) { return parent[static_cast<std::size_t>(k)]; }
}  // namespace

bool factor(std::span<double> h, int nv, std::span<const int> parent, int first) {
  // A row's ancestors come in runs of consecutive dofs (a ball joint's three,
  // a chain of hinges), so the update of an ancestor's row runs over
  // contiguous columns instead of walking the parents. Every entry gets the
  // same operations in the same order as the walk, so the same bits.
  std::array<double, kMaxDofs> hk;   // row k at its ancestors, by column, before the row is scaled
  std::array<int, kMaxDofs> lo, hi;  // the runs, nearest first
  for (int k = nv - 1; k >= first; --k) {
    double* row_k = &h[at(k, 0, nv)];
    const double hkk = row_k[k];
    if (!(hkk > 0.0)) return false;
    std::size_t runs = 0;
    for (int i = up(parent, k); i >= first; i = up(parent, i)) {
      if (runs > 0 && lo[runs - 1] == i + 1) {
        lo[runs - 1] = i;
      } else {
        lo[runs] = hi[runs] = i;
        ++runs;
      }
      hk[static_cast<std::size_t>(i)] = row_k[i];
    }
    for (std::size_t r = 0; r < runs; ++r) {
      for (int i = hi[r]; i >= lo[r]; --i) {
        const double a = hk[static_cast<std::size_t>(i)] / hkk;
        double* row_i = &h[at(i, 0, nv)];
        for (int c = lo[r]; c <= i; ++c) row_i[c] -= a * hk[static_cast<std::size_t>(c)];
        for (std::size_t s = r + 1; s < runs; ++s) {
          for (int c = lo[s]; c <= hi[s]; ++c) row_i[c] -= a * hk[static_cast<std::size_t>(c)];
        }
        row_k[i] = a;
      }
    }
  }
  return true;
}

void solve_lt(std::span<const double> f, int nv, std::span<const int> parent, int first, std::span<double> x) {
  for (int k = nv - 1; k >= first; --k) {
    const double xk = x[static_cast<std::size_t>(k)];
    if (xk == 0.0) continue;  // rows of a contact Jacobian are zero off the contact's path
    for (int i = up(parent, k); i >= first; i = up(parent, i)) x[static_cast<std::size_t>(i)] -= f[at(k, i, nv)] * xk;
  }
}

void solve_lt_on(std::span<const double> f, int nv, std::span<const int> parent, int first, std::uint64_t support,
                 std::span<double> x) {
  // Highest dof first, as solve_lt: a dof's ancestors all have lower indices.
  for (std::uint64_t bits = support; bits != 0;) {
    const int k = 63 - std::countl_zero(bits);
    bits &= ~(std::uint64_t{1} << static_cast<unsigned>(k));
    if (k < first) break;
    const double xk = x[static_cast<std::size_t>(k)];
    if (xk == 0.0) continue;
    for (int i = up(parent, k); i >= first; i = up(parent, i)) x[static_cast<std::size_t>(i)] -= f[at(k, i, nv)] * xk;
  }
}

bool gather_path(std::span<const double> f, int nv, std::span<const int> parent, int first, std::uint64_t support,
                 PathFactor& p) {
  p.support = 0;
  int size = 0, begin = -1, prev = -1;
  for (std::uint64_t bits = support; bits != 0; bits &= bits - 1) {
    const int k = std::countr_zero(bits);
    if (up(parent, k) != prev) return false;  // a branch: not one path
    p.dofs[static_cast<std::size_t>(size)] = static_cast<std::uint8_t>(k);
    if (begin < 0 && k >= first) begin = size;
    prev = k;
    ++size;
  }
  if (begin < 0) begin = size;
  for (int j = begin; j < size; ++j) {
    const int kj = p.dofs[static_cast<std::size_t>(j)];
    for (int i = begin; i < j; ++i)
      p.l[static_cast<std::size_t>(j) * kMaxDofs + static_cast<std::size_t>(i)] =
          f[at(kj, p.dofs[static_cast<std::size_t>(i)], nv)];
  }
  p.support = support;
  p.begin = begin;
  p.size = size;
  return true;
}

void solve_lt_path(const PathFactor& p, std::span<double> x) {
  std::array<double, kMaxDofs> xp;
  const auto begin = static_cast<std::size_t>(p.begin), size = static_cast<std::size_t>(p.size);
  for (std::size_t j = begin; j < size; ++j) xp[j] = x[p.dofs[j]];
  for (std::size_t j = size; j-- > begin;) {
    const double xj = xp[j];
    if (xj == 0.0) continue;
    const double* lj = &p.l[j * kMaxDofs];
    for (std::size_t i = begin; i < j; ++i) xp[i] -= lj[i] * xj;
  }
  for (std::size_t j = begin; j < size; ++j) x[p.dofs[j]] = xp[j];
}

void solve_l(std::span<const double> f, int nv, std::span<const int> parent, int first, std::span<double> x) {
  for (int k = first; k < nv; ++k) {
    double s = x[static_cast<std::size_t>(k)];
    for (int i = up(parent, k); i >= first; i = up(parent, i)) s -= f[at(k, i, nv)] * x[static_cast<std::size_t>(i)];
    x[static_cast<std::size_t>(k)] = s;
  }
}

void solve(std::span<const double> f, int nv, std::span<const int> parent, int first, std::span<double> x) {
  solve_lt(f, nv, parent, first, x);
  for (int k = first; k < nv; ++k) x[static_cast<std::size_t>(k)] /= f[at(k, k, nv)];
  solve_l(f, nv, parent, first, x);
}

}  // namespace tonus::sim::ltdl
