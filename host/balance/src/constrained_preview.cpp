#include "constrained_preview.hpp"

#include <algorithm>
#include <cmath>

namespace tonus::balance::detail {
namespace {
constexpr int kMaxPasses = 12;

// The Cholesky factor U (A = U'U) in place of A's upper triangle, unblocked:
// Eigen's blocked LLT asks the heap for its product's workspace at dynamic
// sizes, and a frame's plan must not allocate. False if A is not positive
// definite (numerically).
bool factor_upper(Eigen::MatrixXd& a) {
  const Eigen::Index n = a.rows();
  for (Eigen::Index j = 0; j < n; ++j) {
    const double d2 = a(j, j) - a.col(j).head(j).squaredNorm();
    if (!(d2 > 0.0)) return false;
    const double d = std::sqrt(d2);
    a(j, j) = d;
    for (Eigen::Index k = j + 1; k < n; ++k) a(j, k) = (a(j, k) - a.col(j).head(j).dot(a.col(k).head(j))) / d;
  }
  return true;
}
}  // namespace

ConstrainedPreview::ConstrainedPreview(const PreviewModel& model, const Eigen::Matrix3d& tail_cost, std::size_t horizon,
                                       double tracking_weight, double jerk_weight, double violation_weight,
                                       std::size_t rows_per_frame)
    : a_(model.A),
      b_(model.B),
      n_(std::max<std::size_t>(horizon, 1)),
      weight_(violation_weight),
      tracking_(tracking_weight),
      per_frame_(std::max<std::size_t>(rows_per_frame, 1)),
      rows_(n_ * per_frame_),
      count_(n_, 0),
      active_(n_ * per_frame_, 0),
      previous_(n_ * per_frame_, 0) {
  const auto n = static_cast<Eigen::Index>(n_);
  g_.setZero(n, n);
  f_.setZero(n, 3);
  gx_.setZero(n, n);
  fx_.setZero(n, 3);
  // The state after j steps is A^j s0 + sum_{i<j} A^(j-1-i) B u_i.
  std::vector<Eigen::Vector3d> powers_b(n_);  // A^k B
  Eigen::Vector3d ab = model.B;
  for (std::size_t k = 0; k < n_; ++k) {
    powers_b[k] = ab;
    ab = model.A * ab;
  }
  Eigen::Matrix3d power = Eigen::Matrix3d::Identity();  // A^j
  for (Eigen::Index j = 1; j <= n; ++j) {
    power = model.A * power;
    f_.row(j - 1) = model.C * power;
    fx_.row(j - 1) = power.row(0);
    for (Eigen::Index i = 0; i < j; ++i) {
      g_(j - 1, i) = model.C.dot(powers_b[static_cast<std::size_t>(j - 1 - i)]);
      gx_(j - 1, i) = powers_b[static_cast<std::size_t>(j - 1 - i)](0);
    }
  }
  Eigen::MatrixXd gn(3, n);  // s_n = A^n s0 + gn u
  for (Eigen::Index i = 0; i < n; ++i) gn.col(i) = powers_b[static_cast<std::size_t>(n - 1 - i)];
  // The tracking over steps 1 .. n - 1: the cost-to-go P already holds step
  // n's (the Riccati equation's stage cost), so the first jerk with no rows is
  // the infinite-horizon regulator's.
  const auto inner = g_.topRows(n - 1);
  const auto inner_f = f_.topRows(n - 1);
  base_ = tracking_weight * inner.transpose() * inner + gn.transpose() * tail_cost * gn;
  base_.diagonal().array() += jerk_weight;
  base_f_ = tracking_weight * inner.transpose() * inner_f + gn.transpose() * tail_cost * power;
  // Beyond the horizon the demand the whole look-ahead shares is taken as held
  // (as the plain preview holds its last reference): the cost-to-go is P about
  // the rest state at that offset, x* (rest_offset), so s_n' P s_n becomes
  // (s_n - e1 x*)' P (s_n - e1 x*).
  tail_ = gn.transpose() * tail_cost.col(0);
  system_.setZero(2 * n, 2 * n);
  rhs_.setZero(2 * n);
  u_.setZero(2 * n);
  for (Eigen::VectorXd* v : {&d0_x_, &d0_y_, &x0_x_, &x0_y_, &x_x_, &x_y_,  &h0_x_, &h0_y_, &h_x_,  &h_y_,
                             &s_xx_, &s_xy_, &s_yy_, &e_x_,  &e_y_, &o_xx_, &o_xy_, &o_yy_, &oe_x_, &oe_y_})
    v->setZero(n);
  h_ = g_;
  ratio_.setOnes(n);
}

void ConstrainedPreview::clear_rows() {
  std::fill(count_.begin(), count_.end(), std::size_t{0});
  ratio_.setOnes();
}

void ConstrainedPreview::set_support_ratio(std::size_t step, double ratio) {
  if (step < 1 || step > n_ || !(ratio > 0.0) || !std::isfinite(ratio)) return;
  ratio_(static_cast<Eigen::Index>(step - 1)) = ratio;
}

bool ConstrainedPreview::add_row(std::size_t step, Bounds what, const Eigen::Vector2d& normal, double bound) {
  if (step < 1 || step > n_) return false;
  std::size_t& c = count_[step - 1];
  if (c >= per_frame_) {
    ++dropped_;
    return false;
  }
  rows_[(step - 1) * per_frame_ + c] = Row{normal, bound, what};
  ++c;
  return true;
}

// Adds G' S G to the three blocks of the system (G lower triangular: its row
// j is nonzero up to column j).
void ConstrainedPreview::add_gram(const Eigen::MatrixXd& g, const Eigen::VectorXd& sxx, const Eigen::VectorXd& sxy,
                                  const Eigen::VectorXd& syy) {
  const auto n = static_cast<Eigen::Index>(n_);
  for (Eigen::Index j = 0; j < n; ++j) {
    if (sxx(j) == 0.0 && sxy(j) == 0.0 && syy(j) == 0.0) continue;
    for (Eigen::Index a = 0; a <= j; ++a) {
      const double ga = g(j, a);
      for (Eigen::Index b = 0; b <= j; ++b) {
        const double gg = ga * g(j, b);
        system_(a, b) += sxx(j) * gg;
        system_(a, n + b) += sxy(j) * gg;
        system_(n + a, n + b) += syy(j) * gg;
      }
    }
  }
}

// The soft optimum of one frame's rows at rest: the least of
// Q |x|^2 + W sum max(0, n . x - h)^2 (at rest the cart's ZMP is its offset;
// a zmp row bounds it times the frame's support ratio).
Eigen::Vector2d ConstrainedPreview::frame_rest(std::size_t j) const {
  Eigen::Vector2d x = Eigen::Vector2d::Zero();
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    Eigen::Matrix2d h = tracking_ * Eigen::Matrix2d::Identity();
    Eigen::Vector2d g = Eigen::Vector2d::Zero();
    for (std::size_t k = 0; k < count_[j]; ++k) {
      const Row& row = rows_[j * per_frame_ + k];
      // At rest a zmp row bounds r x (d = x), an offset row x.
      const Eigen::Vector2d normal =
          row.what == Bounds::zmp ? Eigen::Vector2d(ratio_(static_cast<Eigen::Index>(j)) * row.normal) : row.normal;
      if (normal.dot(x) <= row.bound) continue;
      h += weight_ * normal * normal.transpose();
      g += weight_ * normal * row.bound;
    }
    const Eigen::Vector2d next = h.ldlt().solve(g);
    const bool settled = (next - x).norm() < 1e-12;
    x = next;
    if (settled) break;
  }
  return x;
}

// What every frame of the look-ahead asks for at rest: of the frames' own
// soft optima, the one nearest zero. A demand held over the whole look-ahead
// (a performer leaning for seconds) is held beyond it too, so the plan settles
// on it; one that comes and goes with the steps is not, so the plan returns
// toward zero. (Holding the newest frame's demand instead, or the whole
// window's, follows the estimates' noise and bias: on the Bandai walk the
// independent estimator's count after rose from 82 to 118.)
Eigen::Vector2d ConstrainedPreview::rest_offset() const {
  Eigen::Vector2d best = frame_rest(0);
  for (std::size_t j = 1; j < n_ && best.squaredNorm() > 0.0; ++j) {
    const Eigen::Vector2d r = frame_rest(j);
    if (r.squaredNorm() < best.squaredNorm()) best = r;
  }
  return best;
}

int ConstrainedPreview::step(std::array<Eigen::Vector3d, 2>& state) {
  const auto n = static_cast<Eigen::Index>(n_);
  d0_x_.noalias() = f_ * state[0];
  d0_y_.noalias() = f_ * state[1];
  x0_x_.noalias() = fx_ * state[0];
  x0_y_.noalias() = fx_ * state[1];
  // What the zmp rows bound: d - (1 - r) x, frame by frame.
  for (Eigen::Index j = 0; j < n; ++j) {
    const double c = 1.0 - ratio_(j);
    h_.row(j) = g_.row(j) - c * gx_.row(j);
    h0_x_(j) = d0_x_(j) - c * x0_x_(j);
    h0_y_(j) = d0_y_(j) - c * x0_y_(j);
  }
  // Warm start: last frame's plan, one frame on.
  for (Eigen::Index i = 0; i + 1 < n; ++i) {
    u_(i) = u_(i + 1);
    u_(n + i) = u_(n + i + 1);
  }
  u_(n - 1) = 0.0;
  u_(2 * n - 1) = 0.0;
  const Eigen::Vector2d rest = rest_offset();
  int pass = 0;
  for (; pass < kMaxPasses; ++pass) {
    x_x_.noalias() = gx_ * u_.head(n);
    x_x_ += x0_x_;
    x_y_.noalias() = gx_ * u_.tail(n);
    x_y_ += x0_y_;
    h_x_.noalias() = h_ * u_.head(n);
    h_x_ += h0_x_;
    h_y_.noalias() = h_ * u_.tail(n);
    h_y_ += h0_y_;
    bool same = pass > 0;
    for (Eigen::Index j = 0; j < n; ++j) {
      std::array<double, 5> zs{}, os{};  // xx, xy, yy, ex, ey
      const auto ju = static_cast<std::size_t>(j);
      for (std::size_t k = 0; k < count_[ju]; ++k) {
        const std::size_t idx = ju * per_frame_ + k;
        const Row& row = rows_[idx];
        const bool zmp = row.what == Bounds::zmp;
        const double vx = zmp ? h_x_(j) : x_x_(j), vy = zmp ? h_y_(j) : x_y_(j);
        const unsigned char on = row.normal.x() * vx + row.normal.y() * vy > row.bound ? 1 : 0;
        same = same && on == previous_[idx];
        active_[idx] = on;
        if (on == 0) continue;
        std::array<double, 5>& sum = zmp ? zs : os;
        const double v0x = zmp ? h0_x_(j) : x0_x_(j), v0y = zmp ? h0_y_(j) : x0_y_(j);
        const double c = row.normal.x() * v0x + row.normal.y() * v0y - row.bound;
        sum[0] += row.normal.x() * row.normal.x();
        sum[1] += row.normal.x() * row.normal.y();
        sum[2] += row.normal.y() * row.normal.y();
        sum[3] += row.normal.x() * c;
        sum[4] += row.normal.y() * c;
      }
      s_xx_(j) = weight_ * zs[0];
      s_xy_(j) = weight_ * zs[1];
      s_yy_(j) = weight_ * zs[2];
      e_x_(j) = weight_ * zs[3];
      e_y_(j) = weight_ * zs[4];
      o_xx_(j) = weight_ * os[0];
      o_xy_(j) = weight_ * os[1];
      o_yy_(j) = weight_ * os[2];
      oe_x_(j) = weight_ * os[3];
      oe_y_(j) = weight_ * os[4];
    }
    if (same) break;
    std::copy(active_.begin(), active_.end(), previous_.begin());
    system_.topLeftCorner(n, n) = base_;
    system_.bottomRightCorner(n, n) = base_;
    system_.topRightCorner(n, n).setZero();
    add_gram(h_, s_xx_, s_xy_, s_yy_);
    add_gram(gx_, o_xx_, o_xy_, o_yy_);
    // Products one at a time, each straight into rhs_ (a product inside a
    // sum would be evaluated into a temporary on the heap).
    rhs_.head(n) = tail_ * rest.x();
    rhs_.tail(n) = tail_ * rest.y();
    rhs_.head(n).noalias() -= base_f_ * state[0];
    rhs_.tail(n).noalias() -= base_f_ * state[1];
    rhs_.head(n).noalias() -= h_.transpose() * e_x_;
    rhs_.tail(n).noalias() -= h_.transpose() * e_y_;
    rhs_.head(n).noalias() -= gx_.transpose() * oe_x_;
    rhs_.tail(n).noalias() -= gx_.transpose() * oe_y_;
    if (!factor_upper(system_)) {  // cannot happen with a positive jerk weight; keep the last plan
      ++failed_;
      break;
    }
    u_ = rhs_;
    system_.triangularView<Eigen::Upper>().transpose().solveInPlace(u_);
    system_.triangularView<Eigen::Upper>().solveInPlace(u_);
  }
  state[0] = a_ * state[0] + b_ * u_(0);
  state[1] = a_ * state[1] + b_ * u_(n);
  return pass;
}

}  // namespace tonus::balance::detail
