// cube-on-hand: the paper's goals at full stiffness, the free fall's closed
// form, and a gain low enough that the cube falls (the check can fail).
#include <doctest/doctest.h>

#include <cmath>

#include "experiments/cube_on_hand.hpp"
#include "experiments/reports.hpp"
#include "experiments/scene.hpp"

using namespace tonus::experiments;

TEST_CASE("cube-on-hand: PD + FF holds within 1 mm, PD only sags, both react alike and keep the cube") {
  std::string err;
  const auto m = humanoid_model(err);
  REQUIRE(m);
  CubeOnHandOptions opt;
  opt.settle_s = 1.5;
  opt.after_s = 2.0;
  opt.sweep_hz = {2.0};
  const CubeOnHandResult r = run_cube_on_hand(*m, opt);
  REQUIRE(r.error.empty());
  MESSAGE("hand error PD only " << 1e3 * r.pd_only.hand_error_before_drop_m << " mm, PD + FF "
                                << 1e3 * r.pd_ff.hand_error_before_drop_m << " mm; peaks "
                                << 1e3 * r.pd_only.peak_deflection_m << " / " << 1e3 * r.pd_ff.peak_deflection_m
                                << " mm");
  CHECK(r.pd_ff.hand_error_before_drop_m < 1e-3);
  CHECK(r.pd_only.hand_error_before_drop_m > 5e-3);
  CHECK(std::abs(r.pd_only.peak_deflection_m - r.pd_ff.peak_deflection_m) <=
        0.1 * std::max(r.pd_only.peak_deflection_m, r.pd_ff.peak_deflection_m));
  CHECK(r.pd_only.cube_stayed);
  CHECK(r.pd_ff.cube_stayed);
  for (const Goal& g : cube_goals(r)) CHECK_MESSAGE(g.met, g.what);
  // Free fall: the cube's bottom falls 0.3 m, so it lands after sqrt(2 h / g) (the hand barely moves meanwhile).
  const double fall_s = std::sqrt(2.0 * opt.drop_height_m / 9.81);
  CHECK(r.pd_ff.impact_time_s == doctest::Approx(fall_s).epsilon(0.03));
  // At 2 Hz the arm is too soft: the cube falls off in both modes, and the sweep says so.
  REQUIRE(r.sweep.size() == 1);
  CHECK_FALSE(r.sweep[0].stayed_pd_ff);
  CHECK_FALSE(r.sweep[0].stayed_pd_only);
  // The JSON interface names.
  const nlohmann::json j = to_json(r);
  for (const char* mode : {"pd_only", "pd_ff"}) {
    for (const char* key : {"hand_error_before_drop_m", "peak_deflection_m", "settling_time_s", "cube_stayed"})
      CHECK(j[mode].contains(key));
  }
}
