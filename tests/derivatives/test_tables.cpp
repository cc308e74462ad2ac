// Prints the tables of docs/derivatives.md (skipped by default; run with
//   derivatives_tests -tc="*tables*" --no-skip
// to regenerate them). The bound tests check the same measurements.
#include <doctest/doctest.h>

#include <cstdio>
#include <numbers>

#include "tables.hpp"
#include "tonus/host/derivatives/batch.hpp"

using namespace tonus::derivatives;
using namespace tonus::derivatives::test;

TEST_CASE("tables: sinusoid errors per method" * doctest::skip()) {
  for (Method m : kMethods) {
    std::printf("\n%s: max |error| / (A w) for velocity, / (A w^2) for acceleration, %%, interior / ends\n\n",
                name(m).c_str());
    std::printf("| rate | f (Hz) | vel interior | vel ends | acc interior | acc ends |\n|---|---|---|---|---|---|\n");
    for (double rate : kRates) {
      for (double f : kFreqs) {
        const Errors e = sinusoid_errors(m, rate, f);
        std::printf("| %g | %g | %.3g | %.3g | %.3g | %.3g |\n", rate, f, 100 * e.vel_interior, 100 * e.vel_ends,
                    100 * e.acc_interior, 100 * e.acc_ends);
      }
    }
  }
}

TEST_CASE("tables: noise amplification" * doctest::skip()) {
  std::printf("\nRMS acceleration error / sigma (1/s^2), velocity in brackets (1/s); sigma = 2 mm\n\n");
  std::printf("| rate |");
  for (Method m : kMethods) std::printf(" %s |", name(m).c_str());
  std::printf(" predicted (kalman) |\n|---|---|---|---|---|---|\n");
  for (double rate : kRates) {
    std::printf("| %g |", rate);
    for (Method m : kMethods) {
      const NoiseGain g = measured_noise_gain(m, rate, 0.002, 7);
      std::printf(" %.4g (%.3g) |", g.acc, g.vel);
    }
    const NoiseRms p = predicted_noise(Params{.noise_sigma = 1.0}, 1.0 / rate);
    std::printf(" %.4g (%.3g) |\n", p.acc, p.vel);
  }
}

TEST_CASE("tables: human-like signals" * doctest::skip()) {
  struct Named {
    const char* what;
    Signal s;
  };
  const Named signals[] = {{"foot step 0.5 m in 0.5 s (peak 11.5 m/s^2)", min_jerk_step(0.5, 1.0, 0.5)},
                           {"kick 0.8 m in 0.25 s (peak 74 m/s^2)", min_jerk_step(0.8, 1.0, 0.25)},
                           {"Gaussian bump 0.1 m, sd 0.1 s (peak 10 m/s^2)", gaussian_bump(0.1, 1.25, 0.1)}};
  for (const Named& sig : signals) {
    std::printf("\n%s: max |acc error| m/s^2 (interior / ends), max |vel error| m/s interior\n\n", sig.what);
    std::printf("| rate |");
    for (Method m : kMethods) std::printf(" %s |", name(m).c_str());
    std::printf("\n|---|---|---|---|---|\n");
    for (double rate : kRates) {
      std::printf("| %g |", rate);
      for (Method m : kMethods) {
        const Errors e = signal_errors(m, sig.s, rate, 2.5);
        std::printf(" %.3g / %.3g (%.3g) |", e.acc_interior, e.acc_ends, e.vel_interior);
      }
      std::printf("\n");
    }
  }
}
