#include "tonus/host/derivatives/batch.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "finite_difference.hpp"
#include "spline.hpp"
#include "tonus/host/derivatives/white_jerk.hpp"

namespace tonus::derivatives {

namespace {

bool usable_output(const Strided<double>& v, std::size_t n) {
  return v.empty() || (v.data != nullptr && v.size == n && v.stride > 0);
}

// The RTS smoother: positions, velocities and accelerations (physical units).
// Returns false if the filter never had enough finite samples.
bool rts_smooth(std::span<const double> y, const Params& params, double dt_s, std::span<double> pos,
                std::span<double> vel, std::span<double> acc, Stats& stats) {
  const std::size_t n = y.size();
  WhiteJerkFilter filter(make_model(params, dt_s), params.outlier_gate);
  std::vector<RtsLink> links(n - 1);
  for (std::size_t k = 0; k < n; ++k) {
    if (k > 0) links[k - 1] = filter.predict();
    if (filter.update(y[k]) == WhiteJerkFilter::Update::rejected) ++stats.rejected;
  }
  if (!filter.ready()) return false;
  Eigen::Vector3d s = filter.state();
  for (std::size_t k = n; k-- > 0;) {
    if (k + 1 < n) s = links[k].C * s + links[k].d;
    const Eigen::Vector3d u = filter.unscale(s);
    pos[k] = u[0];
    vel[k] = u[1];
    acc[k] = u[2];
  }
  return true;
}

}  // namespace

Status differentiate(Strided<const double> x, double dt_s, const Params& params, const Outputs& out, Stats* stats) {
  const std::size_t n = x.size;
  if (const Status s = validate(params, dt_s, n); !s) return s;
  if (x.data == nullptr || !usable_output(out.pos, n) || !usable_output(out.vel, n) || !usable_output(out.acc, n)) {
    return {Error::bad_view, 0};
  }
  // A contiguous copy first: outputs may then alias the input.
  std::vector<double> y(n), pos(n), vel(n), acc(n);
  Stats st;
  std::size_t finite = 0, run = 0, first_bad = n;
  for (std::size_t i = 0; i < n; ++i) {
    y[i] = x[i];
    if (std::isfinite(y[i])) {
      ++finite;
      run = 0;
    } else {
      first_bad = std::min(first_bad, i);
      ++st.missing;
      st.longest_gap = std::max(st.longest_gap, ++run);
    }
  }
  const bool kalman = params.method == Method::kalman || params.method == Method::kalman_spline;
  if (!kalman && first_bad < n) return {Error::non_finite_sample, first_bad};
  if (kalman && finite < kMinFiniteSamples) return {Error::too_few_finite_samples, 0};

  switch (params.method) {
    case Method::kalman:
      if (!rts_smooth(y, params, dt_s, pos, vel, acc, st)) return {Error::too_few_finite_samples, 0};
      break;
    case Method::kalman_spline: {
      if (!rts_smooth(y, params, dt_s, pos, vel, acc, st)) return {Error::too_few_finite_samples, 0};
      std::vector<double> scratch(n);
      detail::cubic_spline_derivatives(pos, dt_s, params.spline_end, vel, acc, scratch);
      break;
    }
    case Method::spline: {
      std::vector<double> scratch(n);
      pos = y;
      detail::cubic_spline_derivatives(y, dt_s, params.spline_end, vel, acc, scratch);
      break;
    }
    case Method::finite_difference:
      pos = y;
      detail::finite_differences(y, dt_s, vel, acc);
      break;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!out.pos.empty()) out.pos[i] = pos[i];
    if (!out.vel.empty()) out.vel[i] = vel[i];
    if (!out.acc.empty()) out.acc[i] = acc[i];
  }
  if (stats != nullptr) *stats = st;
  return {};
}

Result differentiate(std::span<const double> x, double dt_s, const Params& params) {
  Result r;
  r.pos.resize(x.size());
  r.vel.resize(x.size());
  r.acc.resize(x.size());
  r.status =
      differentiate(Strided<const double>(x), dt_s, params,
                    Outputs{std::span<double>(r.pos), std::span<double>(r.vel), std::span<double>(r.acc)}, &r.stats);
  if (!r.status) {
    r.pos.clear();
    r.vel.clear();
    r.acc.clear();
  }
  return r;
}

Result3 differentiate(std::span<const Eigen::Vector3d> points, double dt_s, const Params& params) {
  Result3 r;
  r.pos.resize(points.size());
  r.vel.resize(points.size());
  r.acc.resize(points.size());
  for (std::size_t c = 0; c < 3 && r.status; ++c) {
    Stats st;
    r.status = differentiate(
        coordinate(points, c), dt_s, params,
        Outputs{coordinate(std::span(r.pos), c), coordinate(std::span(r.vel), c), coordinate(std::span(r.acc), c)},
        &st);
    r.stats.missing += st.missing;
    r.stats.rejected += st.rejected;
    r.stats.longest_gap = std::max(r.stats.longest_gap, st.longest_gap);
  }
  if (!r.status) {
    r.pos.clear();
    r.vel.clear();
    r.acc.clear();
  }
  return r;
}

}  // namespace tonus::derivatives
