#include "tonus/firmware/biquad.hpp"

#include <cmath>
#include <numbers>

namespace tonus::fw {

namespace {

struct Raw {
  double b0, b1, b2, a0, a1, a2;
};

Biquad normalise(const Raw& r) {
  Biquad c;
  c.b0 = static_cast<float>(r.b0 / r.a0);
  c.b1 = static_cast<float>(r.b1 / r.a0);
  c.b2 = static_cast<float>(r.b2 / r.a0);
  c.a1 = static_cast<float>(r.a1 / r.a0);
  c.a2 = static_cast<float>(r.a2 / r.a0);
  return c;
}

double omega(double f_hz, double fs_hz) { return 2.0 * std::numbers::pi * f_hz / fs_hz; }

// Sum of p_k e^{-j w k} for k = 0..2, as (re, im).
struct Complex {
  double re, im;
};
Complex poly(double p0, double p1, double p2, double w) {
  return {p0 + p1 * std::cos(w) + p2 * std::cos(2.0 * w), -(p1 * std::sin(w) + p2 * std::sin(2.0 * w))};
}
// Group delay of a polynomial in z^-1: Re( sum k p_k e^{-jwk} / sum p_k e^{-jwk} ).
double poly_delay(double p0, double p1, double p2, double w) {
  const Complex d = poly(p0, p1, p2, w);
  const Complex n = poly(0.0, p1, 2.0 * p2, w);
  return (n.re * d.re + n.im * d.im) / (d.re * d.re + d.im * d.im);
}

}  // namespace

double butterworth_q(std::size_t order, std::size_t section) {
  const double theta = static_cast<double>(2 * section + 1) * std::numbers::pi / static_cast<double>(2 * order);
  return 1.0 / (2.0 * std::sin(theta));
}

Biquad design_lowpass(double fs_hz, double fc_hz, double q) {
  const double w0 = omega(fc_hz, fs_hz);
  const double cw = std::cos(w0);
  const double alpha = std::sin(w0) / (2.0 * q);
  return normalise({(1.0 - cw) / 2.0, 1.0 - cw, (1.0 - cw) / 2.0, 1.0 + alpha, -2.0 * cw, 1.0 - alpha});
}

Biquad design_highpass(double fs_hz, double fc_hz, double q) {
  const double w0 = omega(fc_hz, fs_hz);
  const double cw = std::cos(w0);
  const double alpha = std::sin(w0) / (2.0 * q);
  return normalise({(1.0 + cw) / 2.0, -(1.0 + cw), (1.0 + cw) / 2.0, 1.0 + alpha, -2.0 * cw, 1.0 - alpha});
}

Biquad design_notch(double fs_hz, double f0_hz, double bandwidth_hz) {
  const double w0 = omega(f0_hz, fs_hz);
  const double cw = std::cos(w0);
  // alpha = tan(pi B / fs) puts the digital -3 dB points exactly B apart
  // (Orfanidis, Introduction to Signal Processing, 11.3). The cookbook's
  // sin(w0) / 2Q is B only near DC: 2.6-3.9 Hz for the harmonics at 1 kHz.
  const double alpha = std::tan(std::numbers::pi * bandwidth_hz / fs_hz);
  return normalise({1.0, -2.0 * cw, 1.0, 1.0 + alpha, -2.0 * cw, 1.0 - alpha});
}

double magnitude(const Biquad& c, double f_hz, double fs_hz) {
  const double w = omega(f_hz, fs_hz);
  const Complex num = poly(static_cast<double>(c.b0), static_cast<double>(c.b1), static_cast<double>(c.b2), w);
  const Complex den = poly(1.0, static_cast<double>(c.a1), static_cast<double>(c.a2), w);
  return std::sqrt((num.re * num.re + num.im * num.im) / (den.re * den.re + den.im * den.im));
}

double group_delay_samples(const Biquad& c, double f_hz, double fs_hz) {
  const double w = omega(f_hz, fs_hz);
  return poly_delay(static_cast<double>(c.b0), static_cast<double>(c.b1), static_cast<double>(c.b2), w) -
         poly_delay(1.0, static_cast<double>(c.a1), static_cast<double>(c.a2), w);
}

}  // namespace tonus::fw
