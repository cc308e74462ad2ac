// The online filter's planner plans every frame without allocating (counted):
// rows added and cleared, the active set changing, the rest offset solved.
#include <doctest/doctest.h>

#include <array>
#include <cmath>

#include "constrained_preview.hpp"
#include "support/allocation_counter.hpp"
#include "tonus/host/balance/preview_control.hpp"

namespace tonus::balance {
namespace {

TEST_CASE("constrained preview: step allocates nothing") {
  REQUIRE(test::probe_allocation_counter() == 2);
  PreviewOptions o;
  o.preview_frames = 30;
  const PreviewModel m = preview_model(o);
  o.tracking_weight = 6.0;
  const PreviewModel held = preview_model(o);
  REQUIRE(m.ok());
  REQUIRE(held.ok());
  detail::ConstrainedPreview plan(m, held.P, 30, 1.0, 1e-6, 20.0, 18);
  std::array<Eigen::Vector3d, 2> s{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  const std::array<Eigen::Vector2d, 4> normals{Eigen::Vector2d(1, 0), Eigen::Vector2d(-1, 0), Eigen::Vector2d(0, 1),
                                               Eigen::Vector2d(0, -1)};
  int passes = 0;
  test::start_counting_allocations();
  for (int k = 0; k < 240; ++k) {
    plan.clear_rows();
    for (std::size_t j = 1; j <= plan.horizon(); ++j) {
      // A square support 10 cm wide whose centre sways, so rows come and go.
      const double c = 0.08 * std::sin(0.05 * static_cast<double>(k + static_cast<int>(j)));
      plan.set_support_ratio(j, 1.0 + 0.5 * std::cos(0.1 * static_cast<double>(k)));  // a bounce
      for (const Eigen::Vector2d& n : normals)
        plan.add_row(j, detail::ConstrainedPreview::Bounds::zmp, n, 0.05 + n.x() * c);
      plan.add_row(j, detail::ConstrainedPreview::Bounds::offset, Eigen::Vector2d(1, 0), 0.04);
    }
    passes += plan.step(s);
  }
  const long allocations = test::stop_counting_allocations();
  CHECK(allocations == 0);
  CHECK(passes > 240);  // the active set changed: more than one pass on some frames
  CHECK(s[0].allFinite());
}

}  // namespace
}  // namespace tonus::balance
