// Independent references for the derivatives tests: a dense least-squares
// solution of the white-jerk model, the exact interior frequency responses of
// every method, and analytic test signals. Written from the equations in
// docs/derivatives.md, sharing no code with the library.
#pragma once

#include <complex>
#include <cstddef>
#include <functional>
#include <random>
#include <vector>

namespace tonus::derivatives::test {

// p, v, a at each sample (physical units).
struct Pva {
  std::vector<double> p, v, a;
};

// The maximum a posteriori states of the model "white jerk of density q,
// position observed with noise sigma every dt, flat prior", by QR on the
// whitened stacked system (3n unknowns). NaN samples are left out.
Pva dense_map(const std::vector<double>& y, double dt, double sigma, double q);

// Interior (steady-state) response of each method to the sampled complex
// exponential exp(i theta k), theta = 2 pi f dt: position, velocity and
// acceleration outputs as complex multiples of the input sample.
struct Response {
  std::complex<double> p, v, a;
};
Response kalman_response(double theta, double dt, double sigma, double q);         // the smoother's states
Response kalman_spline_response(double theta, double dt, double sigma, double q);  // spline of smoothed p
Response spline_response(double theta, double dt);                                 // spline of raw samples
Response finite_difference_response(double theta, double dt);                      // central differences

// RMS output error per unit white noise (std 1), from a response function:
// sqrt(1/(2 pi) * integral over [-pi, pi] of |H(theta)|^2).
struct Rms {
  double p = 0.0, v = 0.0, a = 0.0;
};
Rms noise_gain(const std::function<Response(double)>& response);

// An analytic signal: position, velocity, acceleration at time t.
struct Signal {
  std::function<double(double)> p, v, a;
};
Signal polynomial(const std::vector<double>& coefficients);  // sum c_i t^i
Signal sinusoid(double amplitude, double freq_hz, double phase);
Signal gaussian_bump(double height, double centre_s, double width_s);
// A foot-like step: rests, moves `distance` along a minimum-jerk profile in
// `duration` from t0, rests again (acceleration continuous, jerk jumps).
Signal min_jerk_step(double distance, double t0, double duration);

// Samples n values at dt (t = k dt), optionally with Gaussian noise.
std::vector<double> sample(const Signal& s, std::size_t n, double dt);
Pva truth(const Signal& s, std::size_t n, double dt);
void add_noise(std::vector<double>& y, double sigma, std::uint64_t seed);

// Largest |estimate - truth| over samples [begin, end).
double max_error(const std::vector<double>& estimate, const std::vector<double>& truth, std::size_t begin,
                 std::size_t end);
double rms_error(const std::vector<double>& estimate, const std::vector<double>& truth, std::size_t begin,
                 std::size_t end);

}  // namespace tonus::derivatives::test
