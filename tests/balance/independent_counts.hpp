// The independent estimator's verdict on a clip and on its corrected, written
// version: frames outside by more than 1 cm before and after, for the tests
// that judge a filter from outside (balance_crosscheck_tests).
#pragma once

#include <doctest/doctest.h>

#include <cstddef>

#include "independent/zmp_estimator.hpp"
#include "tonus/host/motion/clip.hpp"

namespace tonus::balance::test {

struct IndependentCounts {
  std::size_t before = 0, after = 0;
  std::size_t supported = 0;  // of the written clip
};

inline IndependentCounts independent_counts(const motion::Clip& original, const motion::Clip& written, double unit_m,
                                            std::size_t first_frame) {
  indep::Options io;
  io.metres_per_unit = unit_m;
  io.first_frame = first_frame;
  const indep::Estimate before = indep::estimate_zmp(original, io), after = indep::estimate_zmp(written, io);
  REQUIRE(before.ok());
  REQUIRE(after.ok());
  return {before.summary.outside, after.summary.outside, after.summary.supported};
}

}  // namespace tonus::balance::test
