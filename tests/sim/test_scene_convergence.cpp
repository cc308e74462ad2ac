// The benchmark's lively scene (a ball thrown at the standing avatar every
// 400 steps, bench/physics_scenes.hpp) converges step after step: the share
// of steps that end above the residual goal is small, and none of them come
// in long runs. A solver that settles into a cycle (the conjugate-gradient
// momentum pushing a resting toe's impulse below zero and the sweep clipping
// it back, forever) leaves hundreds of steps in a row at the sweep cap.
#include <doctest/doctest.h>

#include <algorithm>

#include "physics_scenes.hpp"
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
