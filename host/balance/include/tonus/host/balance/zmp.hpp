// The zero moment point of a multi-segment body (Vukobratovic; Kajita et al.,
// "Introduction to Humanoid Robotics", ch. 3): the point on the ground where
// the moment of gravity and inertia forces has no horizontal component.
//
//   N   = sum m_i (zdd_i + g)
//   p_x = (sum m_i [(zdd_i + g) x_i - xdd_i (z_i - z0)] - dL_y/dt) / N
//   p_y = (sum m_i [(zdd_i + g) y_i - ydd_i (z_i - z0)] + dL_x/dt) / N
//
// The particle form (segments as point masses, the source method's) drops the
// rate of change of the segments' own angular momentum L; the full form keeps
// it. With N near zero (flight: the body falls freely) the ZMP does not exist.
#pragma once

#include <array>

#include "tonus/host/balance/mass_model.hpp"

namespace tonus::balance {

struct ZmpInputs {
  const SegmentFrame* segments = nullptr;                  // centres of mass
  const std::array<Vec3, kSegmentParts>* accel = nullptr;  // their accelerations
  Vec3 angular_momentum_rate = Vec3::Zero();               // dL/dt about the centres of mass (full form), N*m
};

struct ZmpResult {
  bool defined = false;  // false in flight (vertical force below min_support_ratio of the weight)
  Vec2 zmp = Vec2::Zero();
  double support_ratio = 0.0;  // N / (m g): 1 when standing still, 0 in free fall
};

ZmpResult zero_moment_point(const MassModel& model, const ZmpInputs& in, double ground_z, double gravity = 9.81,
                            double min_support_ratio = 0.1);

// A segment's angular momentum about its centre of mass, from the rate of
// turn of its axis (segments taken as axisymmetric: the transverse radius of
// gyration is the mean of de Leva's sagittal and transverse ones; the spin
// about the axis carries little momentum and is not observable from landmarks).
Vec3 segment_angular_momentum(const MassModel& model, std::size_t part, const SegmentState& s, const Vec3& axis_rate);

}  // namespace tonus::balance
