// quat_from_two_vectors against Eigen's Quaternion::FromTwoVectors (the one
// translation unit that pays for instantiating it): bit for bit wherever the
// directions are not opposite, and a true half turn where they are.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <cstring>
#include <random>

#include "tonus/sim/math.hpp"

using namespace tonus::sim;

namespace {

bool same_bits(const Quat& a, const Quat& b) {
  return std::memcmp(a.coeffs().data(), b.coeffs().data(), 4 * sizeof(double)) == 0;
}

}  // namespace

TEST_CASE("quat_from_two_vectors: Eigen's FromTwoVectors to the bit on random directions and lengths") {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> len(1e-3, 1e3);
  int compared = 0;
  for (int i = 0; i < 10000; ++i) {
    const Vec3 a = Vec3(n(rng), n(rng), n(rng)) * len(rng);
    const Vec3 b =
        (i % 10 == 0 ? Vec3(a + 1e-3 * Vec3(n(rng), n(rng), n(rng))) : Vec3(n(rng), n(rng), n(rng))) * len(rng);
    const Quat ours = quat_from_two_vectors(a, b);
    const Quat eigen = Quat::FromTwoVectors(a, b);
    REQUIRE(same_bits(ours, eigen));
    ++compared;
  }
  CHECK(compared == 10000);
}

TEST_CASE("quat_from_two_vectors: opposite directions turn by a half turn about an axis across them") {
  const Vec3 dirs[] = {Vec3::UnitX(), Vec3::UnitY(),         Vec3::UnitZ(),
                       Vec3(1, 2, 3), Vec3(-0.3, 0.0, 1e-9), Vec3(5, 5, 5)};
  for (const Vec3& d : dirs) {
    for (const Vec3& to : {Vec3(-d), Vec3(-2.0 * d + Vec3(1e-14, 0.0, 0.0))}) {
      const Quat q = quat_from_two_vectors(d, to);
      CHECK(std::abs(q.norm() - 1.0) < 1e-12);
      CHECK((q * d.normalized() - to.normalized()).norm() < 1e-6);
      CHECK(std::abs(q.vec().dot(d.normalized())) < 1e-6);  // the axis is across the direction
      const Quat eigen = Quat::FromTwoVectors(d, to);       // Eigen agrees on where it lands
      CHECK((eigen * d.normalized() - q * d.normalized()).norm() < 1e-6);
    }
  }
}
