// ZMP preview control on the cart-table model: the Riccati solution, the
// closed loop against the cart-table's own equation of motion (the ZMP from
// the centre of mass's second difference, not the model's output matrix),
// and what the preview buys on a step of the reference.
#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "tonus/host/balance/preview_control.hpp"

namespace tonus::balance {
namespace {

constexpr double kG = 9.81;

// Runs the loop on a reference; returns each step's cart ZMP and CoM.
struct Run {
  std::vector<double> zmp, com, jerk;
};
Run follow(const PreviewModel& m, const std::vector<double>& reference) {
  Run run;
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  const std::size_t n = m.preview.size();
  std::vector<double> ahead(n);
  for (std::size_t k = 0; k < reference.size(); ++k) {
    for (std::size_t j = 0; j < n; ++j) ahead[j] = reference[std::min(k + 1 + j, reference.size() - 1)];
    run.zmp.push_back(cart_zmp(m, s));
    run.com.push_back(s.x());
    run.jerk.push_back(preview_step(m, s, ahead));
  }
  return run;
}

TEST_CASE("preview control: the gains solve the Riccati equation") {
  PreviewOptions o;
  const PreviewModel m = preview_model(o);
  REQUIRE_MESSAGE(m.ok(), m.error);
  const double denom = o.jerk_weight + m.B.dot(m.P * m.B);
  const Eigen::RowVector3d pba = m.B.transpose() * m.P * m.A;
  const Eigen::Matrix3d rhs =
      m.A.transpose() * m.P * m.A + m.C.transpose() * o.tracking_weight * m.C - pba.transpose() * pba / denom;
  CHECK((rhs - m.P).norm() <= 1e-9 * m.P.norm());
  // The closed loop is stable: every eigenvalue inside the unit circle.
  const Eigen::Matrix3d closed = m.A - m.B * m.K;
  for (const auto& lambda : closed.eigenvalues()) CHECK(std::abs(lambda) < 1.0);
  REQUIRE(m.preview.size() == o.preview_frames);
  // The preview gains decay: far references matter less (the last one also
  // carries the held tail).
  CHECK(std::abs(m.preview[m.preview.size() - 2]) < std::abs(m.preview.front()));
}

TEST_CASE("preview control: the loop obeys the cart-table equation and settles on a constant reference") {
  PreviewOptions o;
  const PreviewModel m = preview_model(o);
  REQUIRE(m.ok());
  const std::vector<double> reference(static_cast<std::size_t>(4.0 / o.dt_s), 0.05);
  const Run run = follow(m, reference);
  // p = x - (z_c / g) xdd, with xdd from the CoM's own second difference:
  // for a piecewise-constant jerk, x[k+1] - 2 x[k] + x[k-1] = dt^2 xdd[k] +
  // dt^3 (u[k] - u[k-1]) / 6 exactly.
  double worst = 0.0;
  for (std::size_t k = 1; k + 1 < run.com.size(); ++k) {
    const double dt = o.dt_s;
    const double xdd =
        (run.com[k + 1] - 2.0 * run.com[k] + run.com[k - 1]) / (dt * dt) - dt * (run.jerk[k] - run.jerk[k - 1]) / 6.0;
    worst = std::max(worst, std::abs(run.com[k] - o.com_height_m / kG * xdd - run.zmp[k]));
  }
  MESSAGE("cart-table ZMP from the CoM's second difference against the model's: " << worst << " m at worst");
  CHECK(worst < 1e-9);
  CHECK(std::abs(run.zmp.back() - 0.05) < 1e-4);
  CHECK(std::abs(run.com.back() - 0.05) < 1e-4);
}

TEST_CASE("preview control: a longer preview follows a step of the ZMP more closely") {
  const double dt = 1.0 / 120.0;
  std::vector<double> reference(static_cast<std::size_t>(5.0 / dt), 0.0);
  for (std::size_t k = reference.size() / 2; k < reference.size(); ++k) reference[k] = 0.1;
  double previous = 1e9;
  for (const double preview_s : {1.0 / 120.0, 0.25, 0.5, 1.6}) {
    PreviewOptions o;
    o.dt_s = dt;
    o.preview_frames = static_cast<std::size_t>(std::lround(preview_s / dt));
    const PreviewModel m = preview_model(o);
    REQUIRE(m.ok());
    const Run run = follow(m, reference);
    double sum = 0.0, worst = 0.0;
    for (std::size_t k = 0; k < run.zmp.size(); ++k) {
      sum += (run.zmp[k] - reference[k]) * (run.zmp[k] - reference[k]);
      worst = std::max(worst, std::abs(run.zmp[k] - reference[k]));
    }
    const double rms = std::sqrt(sum / static_cast<double>(run.zmp.size()));
    MESSAGE("preview " << preview_s << " s: ZMP error RMS " << rms << " m, largest " << worst << " m");
    CHECK(rms < previous);
    previous = rms;
  }
}

TEST_CASE("preview control: absurd settings are refused") {
  for (const double bad : {0.0, -1.0, std::nan("")}) {
    PreviewOptions o;
    o.dt_s = bad;
    CHECK_FALSE(preview_model(o).ok());
    o = {};
    o.com_height_m = bad;
    CHECK_FALSE(preview_model(o).ok());
    o = {};
    o.jerk_weight = bad;
    CHECK_FALSE(preview_model(o).ok());
  }
}

}  // namespace
}  // namespace tonus::balance
