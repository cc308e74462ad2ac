// The online filter's planner plans every frame without allocating (counted):
// rows added and cleared, the active set changing, the rest offset solved.
// The whole filter's push allocates only where it measures a sole again.
#include <doctest/doctest.h>

#include <array>
#include <cmath>

#include "balance_fixtures.hpp"
#include "constrained_preview.hpp"
#include "support/allocation_counter.hpp"
#include "tonus/host/balance/online_filter.hpp"
#include "tonus/host/balance/preview_control.hpp"

namespace tonus::balance {
namespace {

TEST_CASE("constrained preview: step allocates nothing") {
  REQUIRE(::tonus::test::probe_allocation_counter() == 2);
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
  ::tonus::test::start_counting_allocations();
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
  const long allocations = ::tonus::test::stop_counting_allocations();
  CHECK(allocations == 0);
  CHECK(passes > 240);  // the active set changed: more than one pass on some frames
  CHECK(s[0].allFinite());
}

TEST_CASE("online balance filter: push allocates nothing but where it measures a sole again") {
  // Until 2026-12-05 every push allocated 15-20 times: the support polygon
  // (its soles placed in vectors, the hull's workspace) and the segments'
  // spine polyline. The CMU walk at 120 Hz with 30 frames of look-ahead: the
  // planner, the fine layer and the drop limit all run.
  REQUIRE(::tonus::test::probe_allocation_counter() == 2);
  const test::Loaded l = test::load(test::bundled_clip("cmu_02_walk.bvh"));
  const HumanMotion& m = l.conversion.motion;
  OnlineOptions o;
  o.dt_s = m.dt_s;
  auto created = OnlineBalance::create(o);
  REQUIRE(created);
  OnlineBalance& filter = *created.filter;
  OnlineFrame out;
  std::size_t emitted = 0, quiet = 0, measuring = 0;
  long stray = 0;
  for (std::size_t t = m.first_frame; t < m.size(); ++t) {
    const std::size_t soles = filter.contacts().soles_measured();
    ::tonus::test::start_counting_allocations();
    emitted += filter.push(m.frames[t], out) ? 1U : 0U;
    const long allocations = ::tonus::test::stop_counting_allocations();
    if (filter.contacts().soles_measured() != soles) {
      ++measuring;
    } else {
      ++quiet;
      stray += allocations;
    }
  }
  MESSAGE("CMU walk: " << quiet << " pushes without a sole measured (" << stray << " allocations), " << measuring
                       << " with");
  CHECK(stray == 0);
  CHECK(quiet > 300);
  CHECK(emitted + filter.lookahead_frames() == m.size() - m.first_frame);
  CHECK(out.corrected.p[0].allFinite());
}

}  // namespace
}  // namespace tonus::balance
