// What the daemon tests share: the default humanoid, built once.
#pragma once

#include <memory>

#include <doctest/doctest.h>

#include "tonus/sim/humanoid.hpp"

namespace tonus::test {

inline const sim::Model& daemon_humanoid() {
  static const std::unique_ptr<sim::Model> m = [] {
    sim::BuildResult r = sim::build_humanoid(sim::HumanoidSpec{});
    REQUIRE(r);
    return std::move(r.model);
  }();
  return *m;
}

}  // namespace tonus::test
