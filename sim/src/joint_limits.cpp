// Swing-twist decomposition and the configuration clamp.
#include "tonus/sim/joint_limits.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace tonus::sim {

SwingTwist swing_twist(const Quat& q_in, const Vec3& t) {
  Quat q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Vec3 u = q * t;
  const Vec3 c = t.cross(u);
  const double s = c.norm();
  SwingTwist st;
  st.swing_rad = std::atan2(s, t.dot(u));
  st.swing_axis = s > 1e-12 ? Vec3(c / s) : Vec3::Zero();
  st.twist_rad = 2.0 * std::atan2(q.vec().dot(t), q.w());
  if (st.twist_rad > M_PI) st.twist_rad -= 2.0 * M_PI;
  if (st.twist_rad < -M_PI) st.twist_rad += 2.0 * M_PI;
  return st;
}

bool clamp_ball(const JointLimit& lim, Quat& q) {
  if (!lim.enabled || !std::isfinite(q.norm()) || q.norm() < 1e-9) return false;
  const SwingTwist st = swing_twist(q, lim.twist_axis);
  const double twist = std::clamp(st.twist_rad, lim.lower_rad, lim.upper_rad);
  const double swing = std::min(st.swing_rad, lim.swing_max_rad);
  if (twist == st.twist_rad && swing == st.swing_rad) return false;
  const Quat tw(Eigen::AngleAxisd(twist, lim.twist_axis));
  const Quat sw = st.swing_axis.squaredNorm() > 0.0 ? Quat(Eigen::AngleAxisd(swing, st.swing_axis)) : Quat::Identity();
  q = (sw * tw).normalized();
  return true;
}

bool clamp_hinge(const JointLimit& lim, double& angle_rad) {
  if (!lim.enabled || !std::isfinite(angle_rad)) return false;
  const double x = std::clamp(angle_rad, lim.lower_rad, lim.upper_rad);
  if (x == angle_rad) return false;
  angle_rad = x;
  return true;
}

int clamp_to_limits(const Model& model, std::span<double> qpos) {
  int moved = 0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(model.nbody); ++i) {
    const Body& b = model.bodies[i];
    const auto a = static_cast<std::size_t>(b.qpos_adr);
    if (b.joint == JointType::hinge) {
      moved += clamp_hinge(b.limit, qpos[a]) ? 1 : 0;
    } else if (b.joint == JointType::ball) {
      Quat q(qpos[a], qpos[a + 1], qpos[a + 2], qpos[a + 3]);
      if (!clamp_ball(b.limit, q)) continue;
      qpos[a] = q.w();
      qpos[a + 1] = q.x();
      qpos[a + 2] = q.y();
      qpos[a + 3] = q.z();
      ++moved;
    }
  }
  return moved;
}

}  // namespace tonus::sim
