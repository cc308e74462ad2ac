// The benchmark's lively scene (a ball thrown at the standing avatar every
// 400 steps, bench/physics_scenes.hpp) converges step after step: the share
// of steps that end above the residual goal is small, and none of them come
// in long runs. A solver that settles into a cycle (the conjugate-gradient
// momentum pushing a resting toe's impulse below zero and the sweep clipping
// it back, forever) leaves hundreds of steps in a row at the sweep cap.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstddef>
#include <vector>

#include "physics_scenes.hpp"
#include "support/sanitized.hpp"
#include "tonus/sim/step.hpp"

using namespace tonus;

TEST_CASE("the lively benchmark scene converges: few steps above the residual goal, none in long runs") {
  bench::SceneSpec spec;
  for (const auto& s : bench::benchmark_scenes())
    if (s.name == "lively") spec = s;
  REQUIRE(spec.name == "lively");
  bench::TonusScene scene = bench::make_scene(spec);
  REQUIRE(scene.error.empty());
  scene.settle();
  constexpr int kSteps = 6000;  // fifteen throws
  const double tolerance = scene.model->solver.tolerance;
  int unconverged = 0, run = 0, longest_run = 0;
  for (int i = 0; i < kSteps; ++i) {
    scene.advance();
    const bool over = scene.data->diag.solver_residual > tolerance;
    unconverged += over ? 1 : 0;
    run = over ? run + 1 : 0;
    longest_run = std::max(longest_run, run);
  }
  MESSAGE("unconverged steps: " << unconverged << " of " << kSteps << ", longest run " << longest_run);
  CHECK(unconverged <= kSteps / 100);  // the goal: converged in at least 99 % of steps
  CHECK(longest_run <= 10);
}

// The benchmark's shower100 scene (a hundred 0.1 kg balls dropped in turn on
// the standing avatar, bench/physics_scenes.hpp): the steps where balls land
// on the avatar and roll off its feet are the solver's hardest, and set the
// step time's tail. A subspace step that leaves the residual higher one sweep
// later is kept on trial rather than rejected (solver.cpp); without that these
// steps crawl on momentum alone (over this window: sweeps mean 9.3 and p99
// 88, 20 steps unconverged; with the trial 3.7, 24 and 9).
TEST_CASE("the shower100 benchmark scene: ball landings converge in few sweeps" *
          tonus::test::heavy_under_sanitizers()) {
  bench::SceneSpec spec;
  for (const auto& s : bench::benchmark_scenes())
    if (s.name == "shower100") spec = s;
  REQUIRE(spec.name == "shower100");
  bench::TonusScene scene = bench::make_scene(spec);
  REQUIRE(scene.error.empty());
  scene.settle();
  constexpr int kSteps = 6000;  // four rounds of a hundred drops
  const double tolerance = scene.model->solver.tolerance;
  std::vector<int> sweeps;
  sweeps.reserve(kSteps);
  int unconverged = 0;
  for (int i = 0; i < kSteps; ++i) {
    scene.advance();
    unconverged += scene.data->diag.solver_residual > tolerance ? 1 : 0;
    sweeps.push_back(scene.data->diag.solver_iterations);
  }
  std::sort(sweeps.begin(), sweeps.end());
  const int p99 = sweeps[static_cast<size_t>(kSteps * 99 / 100)];
  double mean = 0.0;
  for (const int s : sweeps) mean += s;
  mean /= kSteps;
  MESSAGE("sweeps mean " << mean << ", p99 " << p99 << ", max " << sweeps.back() << "; unconverged steps "
                         << unconverged << " of " << kSteps);
  CHECK(p99 <= 40);
  CHECK(mean <= 6.0);
  CHECK(unconverged <= kSteps / 400);
}
