// Second-order IIR sections: design (double, once at start-up) and run
// (float, direct form II transposed, on the FPU every sample).
//
// Designs follow R. Bristow-Johnson's "Audio EQ Cookbook": the bilinear
// transform of the analog prototype with the corner prewarped, so the digital
// magnitude at f equals the analog one at Omega = tan(pi f / fs) / tan(pi f0 / fs).
#pragma once

#include <cstddef>

namespace tonus::fw {

// Normalised coefficients (a0 == 1): y = b0 x + b1 x[-1] + b2 x[-2] - a1 y[-1] - a2 y[-2].
struct Biquad {
  float b0 = 1.0F, b1 = 0.0F, b2 = 0.0F, a1 = 0.0F, a2 = 0.0F;
};

// DF2T state: two delay registers, well conditioned in float for poles near z = 1.
struct BiquadState {
  float s1 = 0.0F, s2 = 0.0F;
};

inline float biquad_step(const Biquad& c, BiquadState& s, float x) {
  const float y = c.b0 * x + s.s1;
  s.s1 = c.b1 * x - c.a1 * y + s.s2;
  s.s2 = c.b2 * x - c.a2 * y;
  return y;
}

// Butterworth Q of section k (0-based) of an order-n cascade (n even): 1 / (2 sin((2k+1) pi / (2n))).
double butterworth_q(std::size_t order, std::size_t section);

Biquad design_lowpass(double fs_hz, double fc_hz, double q);
Biquad design_highpass(double fs_hz, double fc_hz, double q);
// Notch at f0 whose -3 dB points lie exactly bandwidth_hz apart (digital domain).
Biquad design_notch(double fs_hz, double f0_hz, double bandwidth_hz);

// Analysis (double precision, from the float coefficients actually run).
double magnitude(const Biquad& c, double f_hz, double fs_hz);
// Group delay -d(phase)/d(omega) in samples.
double group_delay_samples(const Biquad& c, double f_hz, double fs_hz);

}  // namespace tonus::fw
