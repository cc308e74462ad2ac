// Prints the tables of docs/derivatives.md (skipped by default; run with
//   derivatives_tests -tc="*tables*" --no-skip
// to regenerate them). The bound tests check the same measurements.
#include <doctest/doctest.h>

#include <cstdio>
#include <numbers>

#include "tables.hpp"
#include "tonus/host/derivatives/batch.hpp"
#include "tonus/host/derivatives/fixed_lag.hpp"

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

TEST_CASE("tables: fixed-lag error against lag" * doctest::skip()) {
  std::printf("\nFixed lag, fc = 6 Hz. noise: RMS acc difference to the batch smoother on 2 mm noise, / the batch's\n");
  std::printf(
      "own noise RMS; step: max |acc error| on a clean foot step (peak 11.5 m/s^2), m/s^2; noisy step: RMS acc\n");
  std::printf("error with 2 mm noise, m/s^2 (batch kalman in the last row)\n\n");
  std::printf(
      "| rate | lag (frames) | lag (ms) | noise: diff / batch noise | clean step: max acc error | noisy step: RMS acc "
      "error |\n");
  std::printf("|---|---|---|---|---|---|\n");
  for (double rate : {30.0, 120.0}) {
    const double dt = 1.0 / rate;
    const std::size_t n = static_cast<std::size_t>(20 * rate);
    std::vector<double> noise(n, 0.0);
    add_noise(noise, 0.002, 5);
    const Signal step = min_jerk_step(0.5, 1.0, 0.5);
    const std::size_t ns = static_cast<std::size_t>(2.5 * rate);
    const Pva t = truth(step, ns, dt);
    std::vector<double> noisy = sample(step, ns, dt);
    add_noise(noisy, 0.002, 8);
    const Result batch_noise = differentiate(noise, dt, Params{.method = Method::kalman});
    const double floor = rms_error(batch_noise.acc, std::vector<double>(n, 0.0), 50, n - 50);
    const auto run = [&](std::size_t lag, const std::vector<double>& y) {
      auto f = FixedLag::create(dt, {}, lag).smoother;
      std::vector<double> acc(y.size(), 0.0);
      for (double v : y) {
        const Estimate e = f->push(v);
        if (e.valid) acc[e.index] = e.acc;
      }
      for (std::size_t back = lag; back-- > 0;) acc[f->estimate(back).index] = f->estimate(back).acc;
      return acc;
    };
    const std::size_t skip = static_cast<std::size_t>(kEndSeconds * rate);
    for (std::size_t lag : {0u, 1u, 2u, 3u, 5u, 10u, 15u, 20u, 30u}) {
      const double d = rms_error(run(lag, noise), batch_noise.acc, 50, n - 50) / floor;
      const double clean = max_error(run(lag, sample(step, ns, dt)), t.a, skip, ns - skip);
      const double noisy_err = rms_error(run(lag, noisy), t.a, skip, ns - skip);
      std::printf("| %g | %zu | %.0f | %.3g | %.3g | %.3g |\n", rate, lag, 1000.0 * static_cast<double>(lag) * dt, d,
                  clean, noisy_err);
    }
    const Result bc = differentiate(sample(step, ns, dt), dt, Params{.method = Method::kalman});
    const Result bn = differentiate(noisy, dt, Params{.method = Method::kalman});
    std::printf("| %g | batch | | 0 | %.3g | %.3g |\n", rate, max_error(bc.acc, t.a, skip, ns - skip),
                rms_error(bn.acc, t.a, skip, ns - skip));
  }
}

TEST_CASE("tables: choice of the cutoff" * doctest::skip()) {
  std::printf("\nRMS acceleration error (m/s^2, interior, mean of 4 noise seeds) with 2 mm noise against fc\n\n");
  std::printf(
      "| rate | signal | 3 Hz | 4 Hz | 5 Hz | 6 Hz | 8 Hz | 10 Hz | 12 Hz |\n|---|---|---|---|---|---|---|---|---|\n");
  struct Named {
    const char* what;
    Signal s;
  };
  const Named signals[] = {{"foot step 0.5 m / 0.5 s", min_jerk_step(0.5, 1.0, 0.5)},
                           {"kick 0.8 m / 0.25 s", min_jerk_step(0.8, 1.0, 0.25)},
                           {"sway 5 cm at 2 Hz", sinusoid(0.05, 2.0, 0.1)}};
  for (double rate : kRates) {
    for (const Named& sig : signals) {
      std::printf("| %g | %s |", rate, sig.what);
      for (double fc : {3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0}) {
        const double dt = 1.0 / rate;
        const auto n = static_cast<std::size_t>(2.5 * rate);
        const auto skip = static_cast<std::size_t>(kEndSeconds * rate);
        const Pva t = truth(sig.s, n, dt);
        double sum = 0.0;
        for (std::uint64_t seed = 100; seed < 104; ++seed) {
          std::vector<double> y = sample(sig.s, n, dt);
          add_noise(y, 0.002, seed);
          sum += rms_error(differentiate(y, dt, Params{.cutoff_hz = fc}).acc, t.a, skip, n - skip);
        }
        std::printf(" %.2f |", sum / 4.0);
      }
      std::printf("\n");
    }
  }
}
