// Link-time proof that the narrow phase needs no heap and throws nothing: this
// program links the library with every allocation and exception entry point
// poisoned (tonus_poison_heap), so any reference fails the build. Running it
// exercises every pair once.
#include <array>

#include "tonus/sim/collision.hpp"

int main() {
  using namespace tonus::sim;
  const std::array<Shape, 4> shapes = {Shape::sphere(0.1), Shape::capsule(0.05, 0.2), Shape::box({0.1, 0.2, 0.3}),
                                       Shape::plane()};
  const Pose below;
  const Pose above{Vec3(0.01, 0.02, 0.25), Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix()};
  std::array<ContactPoint, kMaxPointsPerPair> out{};
  std::size_t total = 0;
  for (const Shape& a : shapes) {
    for (const Shape& b : shapes) total += collide(a, above, b, below, 0.5, out);
  }
  // 15 pairs touch (plane-plane does not): at least one point each.
  return total >= 15 ? 0 : 1;
}
