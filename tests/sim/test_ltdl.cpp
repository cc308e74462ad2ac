// The sparse LTDL factor (sim/src/ltdl.hpp, private to sim/) against a matrix
// built from a known factor, and the dense path solve against the walking one.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "ltdl.hpp"

using namespace tonus::sim;

namespace {

std::size_t at(int r, int c, int n) {
  return static_cast<std::size_t>(r) * static_cast<std::size_t>(n) + static_cast<std::size_t>(c);
}

// A tree of dofs: 0-5 a chain (a free root), two branches from 5 (6-8 and
// 9-11), and 12-13 hanging from 8.
constexpr int kN = 14;
const std::array<int, kN> kParent{-1, 0, 1, 2, 3, 4, 5, 6, 7, 5, 9, 10, 8, 12};

bool ancestor(int i, int k) {  // i on the path from k to the root (k excluded)
  for (int p = kParent[static_cast<std::size_t>(k)]; p >= 0; p = kParent[static_cast<std::size_t>(p)])
    if (p == i) return true;
  return false;
}

std::uint64_t path_of(int k) {
  std::uint64_t s = 0;
  for (int p = k; p >= 0; p = kParent[static_cast<std::size_t>(p)]) s |= std::uint64_t{1} << static_cast<unsigned>(p);
  return s;
}

}  // namespace

TEST_CASE("ltdl: the factor of L^T D L gives back L and D, the path solve matches the walking one bit for bit") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd l = Eigen::MatrixXd::Identity(kN, kN);
  Eigen::VectorXd d(kN);
  for (int k = 0; k < kN; ++k) {
    d(k) = 0.5 + std::abs(u(rng));
    for (int i = 0; i < k; ++i)
      if (ancestor(i, k)) l(k, i) = u(rng);
  }
  const Eigen::MatrixXd h = l.transpose() * d.asDiagonal() * l;
  std::vector<double> f(static_cast<std::size_t>(kN * kN));
  for (int r = 0; r < kN; ++r)
    for (int c = 0; c < kN; ++c) f[at(r, c, kN)] = h(r, c);
  REQUIRE(ltdl::factor(f, kN, kParent, 0));
  for (int k = 0; k < kN; ++k) {
    CHECK(f[at(k, k, kN)] == doctest::Approx(d(k)).epsilon(1e-12));
    for (int i = 0; i < k; ++i)
      if (ancestor(i, k)) CHECK(f[at(k, i, kN)] == doctest::Approx(l(k, i)).epsilon(1e-10));
  }

  for (const int first : {0, 6}) {  // all dofs, then the root's prescribed
    for (const int leaf : {13, 11, 7}) {
      const std::uint64_t support = path_of(leaf);
      ltdl::PathFactor p;
      REQUIRE(ltdl::gather_path(f, kN, kParent, first, support, p));
      std::array<double, kN> walked{}, packed{};
      for (int k = 0; k < kN; ++k)
        if ((support >> static_cast<unsigned>(k)) & 1U) walked[static_cast<std::size_t>(k)] = u(rng);
      packed = walked;
      const std::array<double, kN> b = walked;
      ltdl::solve_lt_on(f, kN, kParent, first, support, walked);
      ltdl::solve_lt_path(p, packed);
      CHECK(walked == packed);
      // And against a dense solve of L^T x = b on the active dofs.
      if (first == 0) {
        Eigen::VectorXd rhs(kN);
        for (int k = 0; k < kN; ++k) rhs(k) = b[static_cast<std::size_t>(k)];
        const Eigen::VectorXd x = l.transpose().triangularView<Eigen::UnitUpper>().solve(rhs);
        for (int k = 0; k < kN; ++k) CHECK(packed[static_cast<std::size_t>(k)] == doctest::Approx(x(k)).epsilon(1e-10));
      }
    }
  }
}

TEST_CASE("ltdl: a support that branches is not a path") {
  std::vector<double> f(static_cast<std::size_t>(kN * kN), 0.0);
  for (int k = 0; k < kN; ++k) f[at(k, k, kN)] = 1.0;
  ltdl::PathFactor p;
  CHECK_FALSE(ltdl::gather_path(f, kN, kParent, 0, path_of(8) | path_of(11), p));
  CHECK(p.support == 0);
  CHECK(ltdl::gather_path(f, kN, kParent, 0, path_of(8), p));
}
