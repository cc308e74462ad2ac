// The share of the way a first-order low-pass of time constant tau moves
// toward its input in dt (0 < share <= 1; tau <= 0: all the way).
#pragma once

namespace tonus::reference::detail {

inline double first_order_share(double dt_s, double tau_s) { return tau_s > 0.0 ? dt_s / (tau_s + dt_s) : 1.0; }

}  // namespace tonus::reference::detail
