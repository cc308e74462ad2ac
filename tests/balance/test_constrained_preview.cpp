// The constrained preview (the online filter's planner): with no constraint it
// is the infinite-horizon regulator (Bellman: a horizon closed by the Riccati
// cost-to-go gives the same first jerk, -K s, as preview_control.cpp's gains);
// a held half-plane is met where the soft constraint's closed form says; the
// edges couple the axes; a full frame drops rows and counts them.
#include <doctest/doctest.h>

#include <array>
#include <cmath>

#include "constrained_preview.hpp"
#include "tonus/host/balance/preview_control.hpp"

namespace tonus::balance {
namespace {

using detail::ConstrainedPreview;
using Bounds = ConstrainedPreview::Bounds;

PreviewModel model_at(double dt_s, std::size_t frames, double tracking_weight = 1.0) {
  PreviewOptions o;
  o.dt_s = dt_s;
  o.preview_frames = frames;
  o.tracking_weight = tracking_weight;
  return preview_model(o);
}

TEST_CASE("constrained preview: with no rows it is the Riccati regulator, -K s") {
  for (const auto& [dt, frames] : {std::pair{1.0 / 120.0, std::size_t{30}}, std::pair{1.0 / 30.0, std::size_t{8}}}) {
    const PreviewModel m = model_at(dt, frames);
    REQUIRE_MESSAGE(m.ok(), m.error);
    ConstrainedPreview plan(m, m.P, frames, 1.0, 1e-6, 20.0, 4);
    std::array<Eigen::Vector3d, 2> s{Eigen::Vector3d(0.03, -0.1, 0.5), Eigen::Vector3d(-0.02, 0.05, -0.3)};
    std::array<Eigen::Vector3d, 2> lqr = s;
    for (int k = 0; k < 20; ++k) {
      plan.clear_rows();
      plan.step(s);
      for (auto& x : lqr) x = m.A * x + m.B * (-m.K.dot(x));
      for (std::size_t a = 0; a < 2; ++a) CHECK((s[a] - lqr[a]).norm() <= 1e-9 * (1.0 + lqr[a].norm()));
    }
  }
}

TEST_CASE("constrained preview: a held half-plane is met as its soft closed form says") {
  // Every frame ahead asks the cart's ZMP to move at least 5 cm along -y
  // (n = +y, n . d <= -0.05). At rest the cost is Q d^2 + W (d + 0.05)^2 per
  // frame, least at d = -W 0.05 / (Q + W).
  const double w = 20.0, need = 0.05;
  const PreviewModel m = model_at(1.0 / 120.0, 30);
  ConstrainedPreview plan(m, model_at(1.0 / 120.0, 30, 1.0 + w).P, 30, 1.0, 1e-6, w, 4);
  std::array<Eigen::Vector3d, 2> s{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  for (int k = 0; k < 600; ++k) {
    plan.clear_rows();
    for (std::size_t j = 1; j <= plan.horizon(); ++j)
      REQUIRE(plan.add_row(j, Bounds::zmp, Eigen::Vector2d(0, 1), -need));
    plan.step(s);
  }
  const double expected = -w * need / (1.0 + w);
  CHECK(cart_zmp(m, s[1]) == doctest::Approx(expected).epsilon(1e-3));
  CHECK(s[1].x() == doctest::Approx(expected).epsilon(1e-3));  // at rest the offset is the move
  CHECK(std::abs(s[0].x()) < 1e-9);                            // the other axis untouched
  // An offset row caps it: the offset held within 2 cm of zero costs the move.
  for (int k = 0; k < 600; ++k) {
    plan.clear_rows();
    for (std::size_t j = 1; j <= plan.horizon(); ++j) {
      plan.add_row(j, Bounds::zmp, Eigen::Vector2d(0, 1), -need);
      plan.add_row(j, Bounds::offset, Eigen::Vector2d(0, -1), 0.02);
    }
    plan.step(s);
  }
  // Both hinges pull on one offset x: W (x + 0.05) + W (x + 0.02) + Q x = 0.
  CHECK(s[1].x() == doctest::Approx(-w * 0.07 / (1.0 + 2.0 * w)).epsilon(1e-3));
}

TEST_CASE("constrained preview: a frame's support ratio scales the row, not the offset's own move") {
  // At rest the ZMP moves by the offset itself whatever the support ratio r
  // (only the offset's acceleration is amplified, by 1 / r). The filter's
  // rows bound r times the move: r x <= -r 0.05, least of Q x^2 + W (r x +
  // r 0.05)^2 at x = -W r^2 0.05 / (Q + W r^2). (Dividing the cart's ZMP by r,
  // the model before 2026-12-05, gives -W r 0.05 / (Q + W).)
  const double w = 20.0, need = 0.05;
  const PreviewModel m = model_at(1.0 / 120.0, 30);
  for (const double r : {0.5, 2.0}) {
    CAPTURE(r);
    ConstrainedPreview plan(m, model_at(1.0 / 120.0, 30, 1.0 + w * r * r).P, 30, 1.0, 1e-6, w, 4);
    std::array<Eigen::Vector3d, 2> s{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    for (int k = 0; k < 900; ++k) {
      plan.clear_rows();
      for (std::size_t j = 1; j <= plan.horizon(); ++j) {
        plan.set_support_ratio(j, r);
        REQUIRE(plan.add_row(j, Bounds::zmp, Eigen::Vector2d(0, 1), -r * need));
      }
      plan.step(s);
    }
    // Within 6 %: the cost beyond the horizon is a Riccati P on the cart's
    // ZMP alone (exact where r = 1, above), while the rows mix in the offset
    // (r = 0.5: -3.96 cm against -4.17, where the old form gives -2.38; r = 2:
    // -4.93 against -4.94, the old form -9.52).
    const double closed = -w * r * r * need / (1.0 + w * r * r);
    const double old_form = -w * r * need / (1.0 + w);
    MESSAGE("r = " << r << ": settled at " << s[1].x() << " m, closed form " << closed << ", the old form "
                   << old_form);
    CHECK(std::abs(s[1].x() - closed) < 0.06 * std::abs(closed));
    CHECK(std::abs(s[1].x() - old_form) > 0.3 * std::abs(closed));
    CHECK(std::abs(s[1].z()) < 1e-6);  // at rest
  }
}

TEST_CASE("constrained preview: with the online filter's held cost (Q + W / 4) a held violation settles") {
  // online_filter.cpp prices the state beyond the horizon with a quarter of
  // the violation weight: the plan then settles within 2 % of the closed form
  // (with Q alone it runs away: the state grows without bound).
  const double w = 20.0, need = 0.05;
  for (const auto& [dt, frames] : {std::pair{1.0 / 120.0, std::size_t{30}}, std::pair{1.0 / 30.0, std::size_t{8}}}) {
    const PreviewModel m = model_at(dt, frames);
    ConstrainedPreview plan(m, model_at(dt, frames, 1.0 + 0.25 * w).P, frames, 1.0, 1e-6, w, 4);
    std::array<Eigen::Vector3d, 2> s{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    for (int k = 0; k < 2000; ++k) {
      plan.clear_rows();
      for (std::size_t j = 1; j <= plan.horizon(); ++j) plan.add_row(j, Bounds::zmp, Eigen::Vector2d(0, 1), -need);
      plan.step(s);
    }
    CHECK(s[1].x() == doctest::Approx(-w * need / (1.0 + w)).epsilon(0.02));
    CHECK(std::abs(s[1](1)) < 1e-4);  // at rest
  }
}

TEST_CASE("constrained preview: an oblique edge moves both axes along its normal") {
  const double w = 20.0, need = 0.04;
  const PreviewModel m = model_at(1.0 / 30.0, 8);
  ConstrainedPreview plan(m, model_at(1.0 / 30.0, 8, 1.0 + w).P, 8, 1.0, 1e-6, w, 4);
  const Eigen::Vector2d n = Eigen::Vector2d(1.0, 1.0).normalized();
  std::array<Eigen::Vector3d, 2> s{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  for (int k = 0; k < 300; ++k) {
    plan.clear_rows();
    for (std::size_t j = 1; j <= plan.horizon(); ++j) plan.add_row(j, Bounds::zmp, n, -need);
    plan.step(s);
  }
  const Eigen::Vector2d d(cart_zmp(m, s[0]), cart_zmp(m, s[1]));
  CHECK(n.dot(d) == doctest::Approx(-w * need / (1.0 + w)).epsilon(1e-3));
  CHECK(std::abs(d.x() - d.y()) < 1e-6);  // nothing across the normal
}

TEST_CASE("constrained preview: a full frame drops the row and counts it, and steps outside the horizon are refused") {
  const PreviewModel m = model_at(1.0 / 30.0, 8);
  ConstrainedPreview plan(m, m.P, 8, 1.0, 1e-6, 20.0, 2);
  CHECK(plan.add_row(1, Bounds::zmp, Eigen::Vector2d(1, 0), 0.0));
  CHECK(plan.add_row(1, Bounds::zmp, Eigen::Vector2d(0, 1), 0.0));
  CHECK_FALSE(plan.add_row(1, Bounds::zmp, Eigen::Vector2d(-1, 0), 0.0));
  CHECK(plan.dropped_rows() == 1);
  CHECK_FALSE(plan.add_row(0, Bounds::zmp, Eigen::Vector2d(1, 0), 0.0));
  CHECK_FALSE(plan.add_row(9, Bounds::zmp, Eigen::Vector2d(1, 0), 0.0));
  plan.clear_rows();
  CHECK(plan.add_row(1, Bounds::zmp, Eigen::Vector2d(-1, 0), 0.0));
}

}  // namespace
}  // namespace tonus::balance
