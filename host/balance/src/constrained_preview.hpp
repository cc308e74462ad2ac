// Preview control with the support polygon as a constraint (the streaming
// balance filter's planner; issue 14's online variant).
//
// Kajita's preview control follows one reference ZMP move per frame: the move
// that brings the ZMP a margin inside where it is outside, and zero elsewhere.
// Pulling the cart's ZMP back to zero wherever the capture's ZMP is inside
// makes it swing past the edge on frames that were inside (about once a step
// on a walk). Here the frames ahead say where the cart's ZMP move may lie
// instead: for each frame, one half-plane per edge of its support polygon
// (n . d <= h), and the plan over the look-ahead minimises
//   sum_j Q |d_j|^2 + R |u_j|^2 + s_N' P s_N + W sum_rows max(0, n . d_j - h)^2,
// both horizontal axes at once (the polygon's edges couple them), with the
// Riccati solution P as the cost beyond the horizon, about the rest state
// every frame of the look-ahead asks for (rest_offset; the plain preview
// likewise holds its last reference; with no rows the first jerk is the
// infinite-horizon regulator's). Rows may also bound the offset x itself (the
// shift cap, the legs' reach). The hinge is solved by Gauss-Newton on its
// active rows (exact for a piecewise quadratic: it stops when the active set
// repeats). Only the first jerk is applied; the plan is made again next frame.
//
// Everything is sized at construction; step() allocates nothing.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <vector>

#include "tonus/host/balance/preview_control.hpp"

namespace tonus::balance::detail {

class ConstrainedPreview {
 public:
  // `rows_per_frame`: the most half-planes one frame may carry (at least 1).
  // `tail_cost`: the Riccati solution that prices the state beyond the
  // horizon. With the model's own P the first jerk with no rows is the
  // infinite-horizon regulator's; the online filter passes the P of a tracking
  // weight Q + W / 4, since beyond the horizon a held demand still costs (with
  // Q's P alone the plan pushes a held violation past the horizon, frame after
  // frame, and runs away).
  ConstrainedPreview(const PreviewModel& model, const Eigen::Matrix3d& tail_cost, std::size_t horizon,
                     double tracking_weight, double jerk_weight, double violation_weight, std::size_t rows_per_frame);

  void clear_rows();
  // What a row bounds: the cart's ZMP move d, or its offset x (the centre of
  // mass moved).
  enum class Bounds : unsigned char { zmp, offset };
  // At `step` frames ahead (1 .. horizon): normal . (d or x) <= bound. False
  // (the row dropped, counted) when the frame is full.
  bool add_row(std::size_t step, Bounds what, const Eigen::Vector2d& normal, double bound);
  // The frame's support ratio r (its vertical force over the weight; 1 until
  // set, and again after clear_rows). A centre-of-mass offset x moves the ZMP
  // by x - z_c / g * xdd / r: the offset itself is not amplified where the
  // feet carry part of the weight, its acceleration is. The frame's zmp rows
  // then bound r times that move, n . (d - (1 - r) x) <= bound (d = x -
  // z_c / g * xdd, the cart's ZMP), which is d itself where r = 1.
  void set_support_ratio(std::size_t step, double ratio);

  // Plans from the two axes' states (x, xd, xdd each), applies the first jerk
  // and advances the states by one frame. Returns the Gauss-Newton passes made.
  int step(std::array<Eigen::Vector3d, 2>& state);

  [[nodiscard]] std::size_t horizon() const { return n_; }
  [[nodiscard]] std::size_t dropped_rows() const { return dropped_; }
  // Plans whose system could not be factored (the last plan kept); none with
  // a positive jerk weight.
  [[nodiscard]] std::size_t failed_plans() const { return failed_; }

 private:
  struct Row {
    Eigen::Vector2d normal;
    double bound;
    Bounds what;
  };
  [[nodiscard]] Eigen::Vector2d frame_rest(std::size_t frame) const;
  [[nodiscard]] Eigen::Vector2d rest_offset() const;
  void add_gram(const Eigen::MatrixXd& g, const Eigen::VectorXd& sxx, const Eigen::VectorXd& sxy,
                const Eigen::VectorXd& syy);
  Eigen::Matrix3d a_;
  Eigen::Vector3d b_;
  std::size_t n_;
  double weight_;
  double tracking_;
  std::size_t per_frame_;
  Eigen::MatrixXd g_;        // d_j = f_j s0 + g_j u (j = 1 .. n), per axis
  Eigen::MatrixXd h_;        // what the zmp rows bound, d_j - (1 - r_j) x_j: g_ - (1 - r) gx_ (its u part)
  Eigen::VectorXd ratio_;    // per frame, r_j
  Eigen::MatrixXd f_;        // n x 3
  Eigen::MatrixXd gx_, fx_;  // the offset x_j likewise
  Eigen::MatrixXd base_;     // Q G'G + R I + Gn' P Gn (n x n; G over steps 1 .. n - 1), the same for both axes
  Eigen::MatrixXd base_f_;   // Q G'F + Gn' P An (n x 3): the gradient's part from s0
  Eigen::VectorXd tail_;     // Gn' P e1 (n): the gradient's part from the rest offset
  Eigen::MatrixXd system_;   // 2n x 2n
  Eigen::VectorXd rhs_, u_;  // 2n: u_ is the plan (x jerks, then y)
  // n each: the cart's ZMP moves with no jerk, and the offsets with no jerk and with the plan.
  Eigen::VectorXd d0_x_, d0_y_, x0_x_, x0_y_, x_x_, x_y_;
  // n each: what the zmp rows bound (d - (1 - r) x), with no jerk and with the plan.
  Eigen::VectorXd h0_x_, h0_y_, h_x_, h_y_;
  // Per frame, over its active rows of each kind: W sum n n' (xx, xy, yy) and
  // W sum n (n . v0 - h).
  Eigen::VectorXd s_xx_, s_xy_, s_yy_, e_x_, e_y_, o_xx_, o_xy_, o_yy_, oe_x_, oe_y_;
  std::vector<Row> rows_;           // n * per_frame_, frame j's at [j * per_frame_, ...)
  std::vector<std::size_t> count_;  // per frame
  std::vector<unsigned char> active_, previous_;
  std::size_t dropped_ = 0;
  std::size_t failed_ = 0;
};

}  // namespace tonus::balance::detail
