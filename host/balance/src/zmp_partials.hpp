// How a frame's ZMP moves with its segments' positions and accelerations: the
// derivatives of p = M / N (zmp.hpp) at one frame, 2 x 3 per segment. The
// filters chain them with the segments' motion under a correction.
#pragma once

#include <array>

#include "tonus/host/balance/mass_model.hpp"

namespace tonus::balance::detail {

struct ZmpPartials {
  std::array<Eigen::Matrix<double, 2, 3>, kSegmentParts> dpos;
  std::array<Eigen::Matrix<double, 2, 3>, kSegmentParts> dacc;
};

inline ZmpPartials zmp_partials(const MassModel& model, const SegmentFrame& seg,
                                const std::array<Vec3, kSegmentParts>& acc, const Vec2& p, double ground_z, double g) {
  ZmpPartials d;
  double n = 0.0;
  for (std::size_t i = 0; i < kSegmentParts; ++i) n += model.parts[i].mass_kg * (acc[i].z() + g);
  for (std::size_t i = 0; i < kSegmentParts; ++i) {
    const double m = model.parts[i].mass_kg / n;
    const Vec3& c = seg[i].com;
    const Vec3& a = acc[i];
    d.dpos[i] << m * (a.z() + g), 0.0, -m * a.x(), 0.0, m * (a.z() + g), -m * a.y();
    d.dacc[i] << -m * (c.z() - ground_z), 0.0, m * (c.x() - p.x()), 0.0, -m * (c.z() - ground_z), m * (c.y() - p.y());
  }
  return d;
}

}  // namespace tonus::balance::detail
