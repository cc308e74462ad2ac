// brace: the hit segment's peak deflection falls strictly with stiffness, and
// the ball's impulse matches the momentum it brought (m v (1 + e), closed form).
#include <doctest/doctest.h>

#include "experiments/brace.hpp"
#include "experiments/reports.hpp"
#include "experiments/scene.hpp"
#include "support/sanitized.hpp"

using namespace tonus::experiments;

TEST_CASE("brace: a stiffer performer is pushed less, at the chest and at the head" *
          tonus::test::heavy_under_sanitizers()) {
  std::string err;
  const auto m = humanoid_model(err);
  REQUIRE(m);
  BraceOptions opt;
  opt.after_s = 1.5;
  const BraceResult r = run_brace(*m, opt);
  REQUIRE(r.error.empty());
  REQUIRE(r.targets.size() == 2);
  for (const BraceTarget& t : r.targets) {
    INFO(t.name);
    REQUIRE(t.points.size() == 5);
    for (std::size_t i = 0; i < t.points.size(); ++i) {
      CHECK(t.points[i].hit);
      CHECK(t.points[i].final_deflection_m < 0.005);  // back in place: no segment flops onto its limit
      if (i > 0) CHECK(t.points[i].peak_deflection_m < t.points[i - 1].peak_deflection_m);
    }
    CHECK(t.strictly_decreasing);
  }
  // A head-on hit on the chest returns the ball at e = 0.5: impulse m v (1 + e).
  const double expected = opt.ball_mass_kg * opt.ball_speed_mps * 1.5;
  for (const BracePoint& p : r.targets[0].points) CHECK(p.impulse_ns == doctest::Approx(expected).epsilon(0.05));
  for (const Goal& g : brace_goals(r)) CHECK_MESSAGE(g.met, g.what);
}
