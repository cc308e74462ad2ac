// A constraint row's velocity and the effect of an impulse along it, at the
// cost of the row's own size: the articulation's share goes through the
// whitened impulse sum (data.solve_w), an object's through its velocity
// change. Shared by the row assembly (warm start) and the solver. Private to sim/.
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>

#include "tonus/sim/data.hpp"

namespace tonus::sim::detail {

// Rows whose effective inverse mass is below this cannot move anything (a
// kinematic body on the ground): their impulse stays 0.
inline constexpr double kRowMinDiag = 1e-12;

// A normal or limit row's impulse is capped where it alone would change the
// row's velocity by this much (m/s, rad/s). No real contact comes near it (a
// 70 kg avatar standing on a 0.1 kg ball needs 7); it only binds where the
// targets contradict the mechanism (a kinematic root pressing straight legs
// into the floor asks the feet for a velocity no joint can give), and there it
// keeps the impulses finite: a bounded problem always has a solution, an
// unbounded one whose targets cannot be met has none, and its impulses grow
// without limit sweep after sweep.
inline constexpr double kMaxRowSpeedChange = 100.0;

// The number of dofs in a mask. std::popcount is a libgcc call on baseline
// x86-64 (no POPCNT instruction); this is the same count inline.
inline int bit_count(std::uint64_t x) {
  x -= (x >> 1U) & 0x5555555555555555ULL;
  x = (x & 0x3333333333333333ULL) + ((x >> 2U) & 0x3333333333333333ULL);
  x = (x + (x >> 4U)) & 0x0F0F0F0F0F0F0F0FULL;
  return static_cast<int>((x * 0x0101010101010101ULL) >> 56U);
}

// Limit and drive rows act on their joint's own dofs; the others are contact rows.
inline bool is_joint_row(const Data::Row& row) {
  return row.kind == Data::Row::Kind::limit || row.kind == Data::Row::Kind::drive;
}

// Normal and limit rows push only: their impulse lies in [0, bound].
inline bool is_unilateral(const Data::Row& row) {
  return row.kind == Data::Row::Kind::normal || row.kind == Data::Row::Kind::limit;
}

// One past the last row of the drive group that starts at row `first` (a ball
// joint's three rows are projected together).
inline std::size_t drive_group_end(const Data& data, std::size_t first) {
  const int group = data.rows[first].group;
  std::size_t end = first + 1;
  while (end < static_cast<std::size_t>(data.nrows) && data.rows[end].kind == Data::Row::Kind::drive &&
         data.rows[end].group == group)
    ++end;
  return end;
}

// Whether `rows` more rows on `support` fit the Jacobian pool below `limit` entries.
inline bool jacobian_fits(const Data& data, std::uint64_t support, int rows, std::size_t limit) {
  const auto size = static_cast<std::size_t>(bit_count(support));
  return static_cast<std::size_t>(data.jac_used) + size * static_cast<std::size_t>(rows) <= limit;
}

// Appends a row and gives it its place in the Jacobian pool (the caller
// checked the pool's room). False when the rows are full.
inline bool add_row(Data& data, Data::Row& row) {
  if (data.nrows >= static_cast<int>(kMaxRows)) return false;
  row.jac_size = bit_count(row.support);
  row.jac_offset = row.jac_size > 0 ? data.jac_used : -1;
  data.jac_used += row.jac_size;
  data.rows[static_cast<std::size_t>(data.nrows++)] = row;
  return true;
}

// The row's velocity at the current impulses.
inline double row_velocity(const Data& data, const Data::Row& row) {
  double v = row.v0;
  const auto off = static_cast<std::size_t>(row.jac_offset < 0 ? 0 : row.jac_offset);
  for (std::size_t j = 0; j < static_cast<std::size_t>(row.jac_size); ++j)
    v += data.jac_values[off + j] * data.solve_w[data.jac_dofs[off + j]];
  if (row.inv_mass_a > 0.0) {
    const auto i = static_cast<std::size_t>(row.a.index);
    v += row.ua.head<3>().dot(data.obj_dang[i]) + row.ua.tail<3>().dot(data.obj_dlin[i]);
  }
  if (row.inv_mass_b > 0.0) {
    const auto i = static_cast<std::size_t>(row.b.index);
    v += row.ub.head<3>().dot(data.obj_dang[i]) + row.ub.tail<3>().dot(data.obj_dlin[i]);
  }
  return v;
}

// Adds an impulse `delta` along the row to both sides.
inline void apply_row_impulse(Data& data, const Data::Row& row, double delta) {
  const auto off = static_cast<std::size_t>(row.jac_offset < 0 ? 0 : row.jac_offset);
  for (std::size_t j = 0; j < static_cast<std::size_t>(row.jac_size); ++j)
    data.solve_w[data.jac_dofs[off + j]] += data.jac_values[off + j] * delta;
  if (row.inv_mass_a > 0.0) {
    const auto i = static_cast<std::size_t>(row.a.index);
    data.obj_dang[i] += row.ia * delta;
    data.obj_dlin[i] += row.ua.tail<3>() * (row.inv_mass_a * delta);
  }
  if (row.inv_mass_b > 0.0) {
    const auto i = static_cast<std::size_t>(row.b.index);
    data.obj_dang[i] += row.ib * delta;
    data.obj_dlin[i] += row.ub.tail<3>() * (row.inv_mass_b * delta);
  }
}

}  // namespace tonus::sim::detail
