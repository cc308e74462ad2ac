#include "tonus/host/balance/zmp.hpp"

#include <cmath>

namespace tonus::balance {

ZmpResult zero_moment_point(const MassModel& model, const ZmpInputs& in, double ground_z, double gravity,
                            double min_support_ratio) {
  ZmpResult r;
  double n = 0.0, mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < kSegmentParts; ++i) {
    const double m = model.parts[i].mass_kg;
    const Vec3& p = (*in.segments)[i].com;
    const Vec3& a = (*in.accel)[i];
    const double fz = m * (a.z() + gravity);
    n += fz;
    mx += fz * p.x() - m * a.x() * (p.z() - ground_z);
    my += fz * p.y() - m * a.y() * (p.z() - ground_z);
  }
  mx -= in.angular_momentum_rate.y();
  my += in.angular_momentum_rate.x();
  const double weight = model.total_mass_kg * gravity;
  r.support_ratio = weight > 0.0 ? n / weight : 0.0;
  if (!(r.support_ratio >= min_support_ratio)) return r;  // flight, or non-finite input
  r.zmp = Vec2(mx / n, my / n);
  r.defined = std::isfinite(r.zmp.x()) && std::isfinite(r.zmp.y());
  return r;
}

Vec3 segment_angular_momentum(const MassModel& model, std::size_t part, const SegmentState& s, const Vec3& axis_rate) {
  const sim::SegmentParams& p = sim::de_leva(model.parts[part].segment, model.sex);
  const double rg = 0.5 * (p.rg_sagittal + p.rg_transverse) * s.length_m;
  // omega perpendicular to the axis = axis x axis_rate; L = I_t omega.
  return model.parts[part].mass_kg * rg * rg * s.axis.cross(axis_rate);
}

}  // namespace tonus::balance
