// Error measurements shared by the bound tests and the table printer
// (test_tables.cpp), so the documented tables and the tested bounds are the
// same numbers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "reference.hpp"
#include "tonus/host/derivatives/params.hpp"

namespace tonus::derivatives::test {

inline constexpr double kRates[] = {30.0, 60.0, 120.0, 240.0};
inline constexpr double kFreqs[] = {0.5, 1.0, 2.0, 5.0};
inline constexpr Method kMethods[] = {Method::kalman_spline, Method::kalman, Method::spline, Method::finite_difference};
std::string name(Method m);

// Samples within this time of either end count as "ends", the rest as "interior".
inline constexpr double kEndSeconds = 0.25;

// Largest errors over a region, relative to a scale (e.g. A w for velocity).
struct Errors {
  double vel_interior = 0.0, vel_ends = 0.0, acc_interior = 0.0, acc_ends = 0.0;
};

// A clean sinusoid of `freq` Hz over 4 s, errors relative to A w and A w^2,
// worst over eight phases.
Errors sinusoid_errors(Method m, double rate_hz, double freq_hz, const Params& base = {});

// Errors on any signal over `seconds` (absolute, in the signal's units).
Errors signal_errors(Method m, const Signal& s, double rate_hz, double seconds, const Params& base = {});

// RMS velocity and acceleration error per unit noise sigma: a zero signal plus
// seeded Gaussian noise, interior only (methods are linear, so this is the
// noise part of the error for any signal).
struct NoiseGain {
  double vel = 0.0, acc = 0.0;
};
NoiseGain measured_noise_gain(Method m, double rate_hz, double sigma, std::uint64_t seed, const Params& base = {});

}  // namespace tonus::derivatives::test
