#include "reference.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

namespace tonus::derivatives::test {

namespace {

using Cd = std::complex<double>;
using std::numbers::pi;
// The references compute in long double (64-bit mantissa): their own rounding
// then stays well below the 1e-9 the library is held to.
using Real = long double;
using Mat3 = Eigen::Matrix<Real, 3, 3>;
using Cl = std::complex<Real>;

// The model in the state [p, v dt, a dt^2] (scaled by dt, not the library's 1/w_c).
Mat3 transition() {
  Mat3 f;
  f << 1, 1, 0.5, 0, 1, 1, 0, 0, 1;
  return f;
}
// Covariance of the change of [p, v dt, a dt^2] over one step under white jerk
// of density q: the integral over one step of q g g', g = (s^3/6, dt s^2/2, dt^2 s)... scaled.
Mat3 process_noise(double dt, double q) {
  Mat3 n;
  n << 1.0L / 20, 1.0L / 8, 1.0L / 6, 1.0L / 8, 1.0L / 3, 1.0L / 2, 1.0L / 6, 1.0L / 2, 1.0L;
  return static_cast<Real>(q) * std::pow(static_cast<Real>(dt), 5) * n;
}

}  // namespace

Pva dense_map(const std::vector<double>& y, double dt, double sigma, double q) {
  const auto n = static_cast<Eigen::Index>(y.size());
  const Mat3 f = transition();
  // Whitening of the process residual: W = L^-1 with Q = L L'.
  const Mat3 w = process_noise(dt, q).llt().matrixL().solve(Mat3::Identity());
  const auto finite =
      static_cast<Eigen::Index>(std::count_if(y.begin(), y.end(), [](double v) { return std::isfinite(v); }));
  using MatX = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>;
  using VecX = Eigen::Matrix<Real, Eigen::Dynamic, 1>;
  MatX a = MatX::Zero(finite + 3 * (n - 1), 3 * n);
  VecX b = VecX::Zero(a.rows());
  Eigen::Index row = 0;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double yk = y[static_cast<std::size_t>(k)];
    if (!std::isfinite(yk)) continue;
    a(row, 3 * k) = 1.0L / sigma;
    b(row++) = static_cast<Real>(yk) / sigma;
  }
  for (Eigen::Index k = 0; k + 1 < n; ++k, row += 3) {
    a.block<3, 3>(row, 3 * (k + 1)) = w;
    a.block<3, 3>(row, 3 * k) = -w * f;
  }
  const VecX x = a.colPivHouseholderQr().solve(b);
  Pva out;
  for (Eigen::Index k = 0; k < n; ++k) {
    out.p.push_back(static_cast<double>(x(3 * k)));
    out.v.push_back(static_cast<double>(x(3 * k + 1) / dt));
    out.a.push_back(static_cast<double>(x(3 * k + 2) / (dt * dt)));
  }
  return out;
}

Response kalman_response(double theta, double dt, double sigma, double q) {
  // Stationarity of the MAP objective for x_k = X z^k, y_k = z^k (z = e^{i theta}):
  // (F'WF + W - z F'W - z^-1 W F + h h'/R) X = h / R, W = Q^-1.
  using CMat3 = Eigen::Matrix<Cl, 3, 3>;
  using CVec3 = Eigen::Matrix<Cl, 3, 1>;
  const CMat3 f = transition().cast<Cl>();
  const CMat3 wq = process_noise(dt, q).inverse().cast<Cl>();
  const Cl z = std::polar(1.0L, static_cast<Real>(theta));
  CMat3 m = f.transpose() * wq * f + wq - z * f.transpose() * wq - (1.0L / z) * wq * f;
  const Real r = static_cast<Real>(sigma) * sigma;
  m(0, 0) += 1.0L / r;
  CVec3 rhs = CVec3::Zero();
  rhs(0) = 1.0L / r;
  const CVec3 x = m.fullPivLu().solve(rhs);
  const auto to_d = [](Cl c) { return Cd(static_cast<double>(c.real()), static_cast<double>(c.imag())); };
  return {to_d(x(0)), to_d(x(1)) / dt, to_d(x(2)) / (dt * dt)};
}

Response spline_response(double theta, double dt) {
  // Uniform cubic spline: s_{k-1} + 4 s_k + s_{k+1} = 3 (y_{k+1} - y_{k-1}) / h and
  // M_{k-1} + 4 M_k + M_{k+1} = 6 (y_{k+1} - 2 y_k + y_{k-1}) / h^2.
  const double c = std::cos(theta);
  return {1.0, Cd(0.0, 3.0 * std::sin(theta) / ((c + 2.0) * dt)), 6.0 * (c - 1.0) / ((c + 2.0) * dt * dt)};
}

Response kalman_spline_response(double theta, double dt, double sigma, double q) {
  const Response k = kalman_response(theta, dt, sigma, q);
  const Response s = spline_response(theta, dt);
  return {k.p, k.p * s.v, k.p * s.a};
}

Response finite_difference_response(double theta, double dt) {
  return {1.0, Cd(0.0, std::sin(theta) / dt), 2.0 * (std::cos(theta) - 1.0) / (dt * dt)};
}

Rms noise_gain(const std::function<Response(double)>& response) {
  // Periodic integrand: the trapezoidal rule converges fast.
  constexpr int kPoints = 4096;
  Rms sum;
  for (int i = 0; i < kPoints; ++i) {
    const Response r = response(-pi + 2.0 * pi * (i + 0.5) / kPoints);
    sum.p += std::norm(r.p);
    sum.v += std::norm(r.v);
    sum.a += std::norm(r.a);
  }
  return {std::sqrt(sum.p / kPoints), std::sqrt(sum.v / kPoints), std::sqrt(sum.a / kPoints)};
}

Signal polynomial(const std::vector<double>& c) {
  Signal s;
  s.p = [c](double t) {
    double r = 0.0;
    for (std::size_t i = c.size(); i-- > 0;) r = r * t + c[i];
    return r;
  };
  s.v = [c](double t) {
    double r = 0.0;
    for (std::size_t i = c.size(); i-- > 1;) r = r * t + static_cast<double>(i) * c[i];
    return r;
  };
  s.a = [c](double t) {
    double r = 0.0;
    for (std::size_t i = c.size(); i-- > 2;) r = r * t + static_cast<double>(i * (i - 1)) * c[i];
    return r;
  };
  return s;
}

Signal sinusoid(double amplitude, double freq_hz, double phase) {
  const double w = 2.0 * pi * freq_hz;
  return {[=](double t) { return amplitude * std::sin(w * t + phase); },
          [=](double t) { return amplitude * w * std::cos(w * t + phase); },
          [=](double t) { return -amplitude * w * w * std::sin(w * t + phase); }};
}

Signal gaussian_bump(double height, double centre_s, double width_s) {
  const auto g = [=](double t) {
    const double u = (t - centre_s) / width_s;
    return height * std::exp(-0.5 * u * u);
  };
  return {g, [=](double t) { return -g(t) * (t - centre_s) / (width_s * width_s); },
          [=](double t) {
            const double u = (t - centre_s) / width_s;
            return g(t) * (u * u - 1.0) / (width_s * width_s);
          }};
}

Signal min_jerk_step(double distance, double t0, double duration) {
  const auto u = [=](double t) { return std::clamp((t - t0) / duration, 0.0, 1.0); };
  return {[=](double t) {
            const double s = u(t);
            return distance * s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
          },
          [=](double t) {
            const double s = u(t);
            return distance / duration * 30.0 * s * s * (1.0 - s) * (1.0 - s);
          },
          [=](double t) {
            const double s = u(t);
            return distance / (duration * duration) * 60.0 * s * (1.0 - s) * (1.0 - 2.0 * s);
          }};
}

std::vector<double> sample(const Signal& s, std::size_t n, double dt) {
  std::vector<double> y(n);
  for (std::size_t k = 0; k < n; ++k) y[k] = s.p(static_cast<double>(k) * dt);
  return y;
}

Pva truth(const Signal& s, std::size_t n, double dt) {
  Pva out;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * dt;
    out.p.push_back(s.p(t));
    out.v.push_back(s.v(t));
    out.a.push_back(s.a(t));
  }
  return out;
}

void add_noise(std::vector<double>& y, double sigma, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  for (double& v : y) v += noise(rng);
}

double max_error(const std::vector<double>& estimate, const std::vector<double>& truth, std::size_t begin,
                 std::size_t end) {
  double m = 0.0;
  for (std::size_t i = begin; i < end; ++i) m = std::max(m, std::abs(estimate[i] - truth[i]));
  return m;
}

double rms_error(const std::vector<double>& estimate, const std::vector<double>& truth, std::size_t begin,
                 std::size_t end) {
  double s = 0.0;
  for (std::size_t i = begin; i < end; ++i) s += (estimate[i] - truth[i]) * (estimate[i] - truth[i]);
  return std::sqrt(s / static_cast<double>(end - begin));
}

}  // namespace tonus::derivatives::test
