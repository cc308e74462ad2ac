// Contacts and joint limits as velocity-level constraints, solved together by
// projected Gauss-Seidel on the effective-mass (Delassus) matrix
// A = J M~^-1 J^T, where M~ already holds the implicit drives: a stiff drive
// resists a contact exactly as the step will integrate it.
//
// A is formed through the sparse factor: with M~ = L^T D L, the row
// y = D^-1/2 L^-T J^T is non-zero only on the dofs of the row's path(s) to the
// root, so A_rs = y_r . y_s costs the length of the common path.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>

#include "ltdl.hpp"
#include "spatial.hpp"
#include "stages.hpp"
#include "tonus/sim/joint_limits.hpp"

namespace tonus::sim::detail {
namespace {

using std::size_t;
using Row = Data::Row;

Vec6 side_row(const Data& data, const ContactSide& s, const Vec3& p, const Vec3& dir) {
  if (s.kind == ContactSide::Kind::body) return spatial::make((p - data.origin).cross(dir), dir);
  if (s.kind == ContactSide::Kind::object) {
    return spatial::make((p - data.objects[static_cast<size_t>(s.index)].pos).cross(dir), dir);
  }
  return Vec6::Zero();
}

std::uint64_t side_support(const Model& model, const ContactSide& s) {
  return s.kind == ContactSide::Kind::body ? model.body_path_dofs[static_cast<size_t>(s.index)] : 0;
}

bool add_row(Data& data, const Row& r) {
  if (data.nrows >= static_cast<int>(kMaxRows)) return false;
  data.rows[static_cast<size_t>(data.nrows++)] = r;
  return true;
}

void limit_row(const Model& model, Data& data, int body, const Vec3& coef, double dist) {
  if (data.njoint_rows >= static_cast<int>(kMaxJointRows)) {
    ++data.diag.limit_overflow;
    return;
  }
  const double dt = model.timestep_s;
  Row r;
  r.kind = Row::Kind::limit;
  r.limit_body = body;
  r.limit_coef = coef;
  r.support = model.body_path_dofs[static_cast<size_t>(body)];
  // Speculative while inside the range (may close the gap, not cross it);
  // Baumgarte-corrected once outside.
  r.target = dist > 0.0 ? -dist / dt : -model.solver.baumgarte * dist / dt;
  if (add_row(data, r)) {
    ++data.njoint_rows;
  } else {
    ++data.diag.limit_overflow;
  }
}

void build_limit_rows(const Model& model, Data& data) {
  const double dt = model.timestep_s;
  for (size_t i = 0; i < static_cast<size_t>(model.nbody); ++i) {
    const Body& b = model.bodies[i];
    if (!b.limit.enabled) continue;
    const auto q0 = static_cast<size_t>(b.qpos_adr);
    const auto d0 = static_cast<size_t>(b.dof_adr);
    const double margin = model.solver.limit_margin_rad;
    if (b.joint == JointType::hinge) {
      const double q = data.qpos[q0], v = data.qvel[d0];
      const double reach = margin + std::abs(v) * dt;
      if (q - b.limit.lower_rad < reach)
        limit_row(model, data, static_cast<int>(i), Vec3(1, 0, 0), q - b.limit.lower_rad);
      if (b.limit.upper_rad - q < reach)
        limit_row(model, data, static_cast<int>(i), Vec3(-1, 0, 0), b.limit.upper_rad - q);
    } else if (b.joint == JointType::ball) {
      const Quat q(data.qpos[q0], data.qpos[q0 + 1], data.qpos[q0 + 2], data.qpos[q0 + 3]);
      const Vec3 w(data.qvel[d0], data.qvel[d0 + 1], data.qvel[d0 + 2]);
      const Vec3& t = b.limit.twist_axis;
      const SwingTwist st = swing_twist(q, t);
      const double reach = margin + w.norm() * dt;
      if (b.limit.swing_max_rad - st.swing_rad < reach && st.swing_axis.squaredNorm() > 0.0) {
        // d(swing)/dt = axis . (R(q) w): the row is -(R(q)^T axis).
        const Vec3 coef = -(q.normalized().toRotationMatrix().transpose() * st.swing_axis);
        limit_row(model, data, static_cast<int>(i), coef, b.limit.swing_max_rad - st.swing_rad);
      }
      // Twist rate taken as the spin about the body's own axis (exact without swing).
      if (st.twist_rad - b.limit.lower_rad < reach)
        limit_row(model, data, static_cast<int>(i), t, st.twist_rad - b.limit.lower_rad);
      if (b.limit.upper_rad - st.twist_rad < reach)
        limit_row(model, data, static_cast<int>(i), -t, b.limit.upper_rad - st.twist_rad);
    }
  }
}

// Row velocity for a side given spatial velocities (bodies) or object velocities.
double side_velocity(const Data& data, const ContactSide& s, const Vec6& u, bool next) {
  if (s.kind != ContactSide::Kind::object) return 0.0;
  const auto i = static_cast<size_t>(s.index);
  const Vec3 w = next ? data.obj_ang_free[i] : data.objects[i].ang_vel;
  const Vec3 v = next ? data.obj_lin_free[i] : data.objects[i].lin_vel;
  return u.head<3>().dot(w) + u.tail<3>().dot(v);
}

double object_coupling(const Data& data, const ContactSide& s, const Vec6& u1, const Vec6& u2) {
  const auto i = static_cast<size_t>(s.index);
  return u1.head<3>().dot(data.obj_inv_inertia[i] * u2.head<3>()) +
         u1.tail<3>().dot(u2.tail<3>()) / data.objects[i].mass_kg;
}

bool is_object(const ContactSide& s) { return s.kind == ContactSide::Kind::object; }
bool is_joint_row(const Row& r) { return r.kind == Row::Kind::limit || r.kind == Row::Kind::drive; }

}  // namespace

void build_rows(const Model& model, Data& data) {
  data.nrows = 0;
  data.njoint_rows = 0;
  for (int ci = 0; ci < data.ncon; ++ci) {
    const Contact& c = data.contacts[static_cast<size_t>(ci)];
    const std::uint64_t support = side_support(model, c.a) | side_support(model, c.b);
    const Vec3 dirs[3] = {c.normal, c.tangent1, c.tangent2};
    const int nrow = c.friction > 0.0 ? 3 : 1;
    if (data.nrows + nrow > static_cast<int>(kMaxRows - kMaxJointRows)) {
      ++data.diag.contact_overflow;
      continue;
    }
    for (int k = 0; k < nrow; ++k) {
      Row r;
      r.kind = k == 0 ? Row::Kind::normal : (k == 1 ? Row::Kind::friction1 : Row::Kind::friction2);
      r.a = c.a;
      r.b = c.b;
      r.ua = side_row(data, c.a, c.pos, dirs[k]);
      r.ub = -side_row(data, c.b, c.pos, dirs[k]);
      r.contact = ci;
      r.support = support;
      r.lambda = c.impulse(k);  // warm start
      add_row(data, r);
    }
  }
  if (model.features.limits) build_limit_rows(model, data);
  data.nbase_rows = data.nrows;
}

void assemble_rows(const Model& model, Data& data) {
  const int nv = model.nv;
  const int first = data.first_active_dof;
  const auto unv = static_cast<size_t>(nv);
  const int n = data.nrows;
  const auto un = static_cast<size_t>(n);
  const std::uint64_t active = first >= 64 ? 0 : ~((std::uint64_t{1} << static_cast<unsigned>(first)) - 1);
  const double dt = model.timestep_s;
  std::array<double, kMaxDofs> inv_sqrt_d;
  for (int k = first; k < nv; ++k) {
    const auto ku = static_cast<size_t>(k);
    inv_sqrt_d[ku] = 1.0 / std::sqrt(data.factor[ku * unv + ku]);
  }

  for (size_t r = 0; r < un; ++r) {
    Row& row = data.rows[r];
    double* y = &data.row_y[r * kMaxDofs];
    std::fill_n(y, unv, 0.0);
    // J on the articulation.
    if (is_joint_row(row)) {
      const Body& b = model.bodies[static_cast<size_t>(row.limit_body)];
      for (int k = 0; k < b.dof_num; ++k) y[b.dof_adr + k] = row.limit_coef(k);
    } else {
      for (const auto* side : {&row.a, &row.b}) {
        if (side->kind != ContactSide::Kind::body) continue;
        const Vec6& u = side == &row.a ? row.ua : row.ub;
        for (std::uint64_t bits = model.body_path_dofs[static_cast<size_t>(side->index)]; bits != 0; bits &= bits - 1) {
          const auto k = static_cast<size_t>(std::countr_zero(bits));
          y[k] += u.dot(data.cdof[k]);
        }
      }
    }
    double v_pre = side_velocity(data, row.a, row.ua, false) + side_velocity(data, row.b, row.ub, false);
    double v_free = side_velocity(data, row.a, row.ua, true) + side_velocity(data, row.b, row.ub, true);
    for (std::uint64_t bits = row.support; bits != 0; bits &= bits - 1) {
      const auto k = static_cast<size_t>(std::countr_zero(bits));
      v_pre += y[k] * data.qvel[k];
      v_free += y[k] * data.qvel_free[k];
    }
    data.row_pre[r] = v_pre;
    data.row_v0[r] = v_free;
    for (int k = 0; k < first; ++k) y[k] = 0.0;  // prescribed dofs do not yield
    ltdl::solve_lt(data.factor, nv, model.dof_parent, first, std::span<double>(y, unv));
    for (int k = first; k < nv; ++k) y[k] *= inv_sqrt_d[static_cast<size_t>(k)];
  }

  // A = J M~^-1 J^T (symmetric, stored whole for row-contiguous sweeps).
  for (size_t r = 0; r < un; ++r) {
    const Row& rr = data.rows[r];
    const double* yr = &data.row_y[r * kMaxDofs];
    for (size_t s = 0; s <= r; ++s) {
      const Row& rs = data.rows[s];
      const double* ys = &data.row_y[s * kMaxDofs];
      double a = 0.0;
      for (std::uint64_t bits = rr.support & rs.support & active; bits != 0; bits &= bits - 1) {
        const auto k = static_cast<size_t>(std::countr_zero(bits));
        a += yr[k] * ys[k];
      }
      if (!is_joint_row(rr) && !is_joint_row(rs)) {
        if (is_object(rr.a) && is_object(rs.a) && rr.a.index == rs.a.index)
          a += object_coupling(data, rr.a, rr.ua, rs.ua);
        if (is_object(rr.a) && is_object(rs.b) && rr.a.index == rs.b.index)
          a += object_coupling(data, rr.a, rr.ua, rs.ub);
        if (is_object(rr.b) && is_object(rs.a) && rr.b.index == rs.a.index)
          a += object_coupling(data, rr.b, rr.ub, rs.ua);
        if (is_object(rr.b) && is_object(rs.b) && rr.b.index == rs.b.index)
          a += object_coupling(data, rr.b, rr.ub, rs.ub);
      }
      data.delassus[r * un + s] = a;
      data.delassus[s * un + r] = a;
    }
  }

  // Normal-row targets: restitution on real impacts, otherwise close the gap
  // without overshooting (speculative) or push a penetration out (Baumgarte).
  for (size_t r = 0; r < un; ++r) {
    Row& row = data.rows[r];
    if (row.kind != Row::Kind::normal) continue;
    const Contact& c = data.contacts[static_cast<size_t>(row.contact)];
    const double approach = data.row_pre[r];
    const double d = c.dist_m;
    if (c.restitution > 0.0 && approach < -model.solver.restitution_threshold_mps && d + approach * dt < 0.0) {
      row.target = -c.restitution * approach;
    } else if (d > 0.0) {
      row.target = -d / dt;
    } else {
      row.target = model.solver.baumgarte * std::max(0.0, -d - model.solver.penetration_slop_m) / dt;
    }
  }
}

void solve_rows(const Model& model, Data& data) {
  const auto n = static_cast<size_t>(data.nrows);
  const SolverOptions& opt = model.solver;
  int iter = 0;
  double residual = 0.0;
  const auto row_velocity = [&](size_t r) {
    const double* a = &data.delassus[r * n];
    double v = data.row_v0[r];
    for (size_t s = 0; s < n; ++s) v += a[s] * data.rows[s].lambda;
    return v;
  };
  for (iter = 0; iter < opt.iterations; ++iter) {
    residual = 0.0;
    for (size_t r = 0; r < n; ++r) {
      Row& row = data.rows[r];
      const double arr = data.delassus[r * n + r];
      if (!(arr > 1e-12)) {  // nothing can move along this row (e.g. a kinematic body on the ground)
        row.lambda = 0.0;
        continue;
      }
      if (row.kind == Row::Kind::normal || row.kind == Row::Kind::limit) {
        const double next = std::max(0.0, row.lambda + (row.target - row_velocity(r)) / arr);
        residual = std::max(residual, std::abs(next - row.lambda) * arr);
        row.lambda = next;
      } else if (row.kind == Row::Kind::drive) {
        // A drive's rows (one per dof of the joint), each a compliant target,
        // then the group's torque bounded as a vector.
        const auto first = static_cast<size_t>(row.group);
        size_t last = first;
        while (last + 1 < n && data.rows[last + 1].kind == Row::Kind::drive && data.rows[last + 1].group == row.group)
          ++last;
        double norm2 = 0.0;
        std::array<double, 3> next{};
        for (size_t k = first; k <= last; ++k) {
          Row& rk = data.rows[k];
          const double akk = data.delassus[k * n + k] + rk.cfm;
          next[k - first] = rk.lambda + (rk.target - row_velocity(k) - rk.cfm * rk.lambda) / akk;
          norm2 += next[k - first] * next[k - first];
        }
        const double norm = std::sqrt(norm2);
        const double scale = norm > row.bound ? row.bound / norm : 1.0;
        for (size_t k = first; k <= last; ++k) {
          Row& rk = data.rows[k];
          const double l = next[k - first] * scale;
          residual = std::max(residual, std::abs(l - rk.lambda) * (data.delassus[k * n + k] + rk.cfm));
          rk.lambda = l;
        }
        r = last;
      } else if (row.kind == Row::Kind::friction1) {
        // Both tangent rows, then projection onto the Coulomb disc.
        Row& row2 = data.rows[r + 1];
        const double a22 = data.delassus[(r + 1) * n + r + 1];
        const double l1 = row.lambda - row_velocity(r) / arr;
        double l2 = row2.lambda;
        if (a22 > 1e-12) l2 = row2.lambda - row_velocity(r + 1) / a22;
        const Contact& c = data.contacts[static_cast<size_t>(row.contact)];
        const double cap = c.friction * data.rows[r - 1].lambda;
        const double norm = std::hypot(l1, l2);
        const double scale = norm > cap ? (norm > 0.0 ? cap / norm : 0.0) : 1.0;
        residual =
            std::max({residual, std::abs(l1 * scale - row.lambda) * arr, std::abs(l2 * scale - row2.lambda) * a22});
        row.lambda = l1 * scale;
        row2.lambda = l2 * scale;
        ++r;  // friction2 done with it
      }
    }
    if (residual <= opt.tolerance) {
      ++iter;
      break;
    }
  }
  data.diag.solver_iterations = iter;
  data.diag.solver_residual = residual;
  if (n > 0 && residual > opt.tolerance) ++data.diag.solver_unconverged;
}

void apply_impulses(const Model& model, Data& data) {
  const int nv = model.nv;
  const int first = data.first_active_dof;
  const auto unv = static_cast<size_t>(nv);
  const auto n = static_cast<size_t>(data.nrows);
  std::array<double, kMaxDofs> z{};
  for (size_t r = 0; r < n; ++r) {
    const double l = data.rows[r].lambda;
    if (l == 0.0) continue;
    const double* y = &data.row_y[r * kMaxDofs];
    for (size_t k = 0; k < unv; ++k) z[k] += y[k] * l;
  }
  for (int k = first; k < nv; ++k) {
    const auto ku = static_cast<size_t>(k);
    z[ku] /= std::sqrt(data.factor[ku * unv + ku]);
  }
  ltdl::solve_l(data.factor, nv, model.dof_parent, first, std::span<double>(z).first(unv));
  for (size_t k = 0; k < unv; ++k) data.qvel_next[k] = data.qvel_free[k] + (static_cast<int>(k) >= first ? z[k] : 0.0);

  for (size_t i = 0; i < kMaxObjects; ++i) {
    data.obj_lin_next[i] = data.obj_lin_free[i];
    data.obj_ang_next[i] = data.obj_ang_free[i];
  }
  for (size_t r = 0; r < n; ++r) {
    const Row& row = data.rows[r];
    if (is_joint_row(row) || row.lambda == 0.0) continue;
    for (const auto* side : {&row.a, &row.b}) {
      if (!is_object(*side)) continue;
      const Vec6& u = side == &row.a ? row.ua : row.ub;
      const auto i = static_cast<size_t>(side->index);
      data.obj_lin_next[i] += u.tail<3>() * (row.lambda / data.objects[i].mass_kg);
      data.obj_ang_next[i] += data.obj_inv_inertia[i] * u.head<3>() * row.lambda;
    }
  }
}

void report_contacts(const Model& model, Data& data) {
  const double dt = model.timestep_s;
  for (int i = 0; i < data.ncon; ++i) data.contacts[static_cast<size_t>(i)].impulse.setZero();
  for (int r = 0; r < data.nrows; ++r) {
    const Row& row = data.rows[static_cast<size_t>(r)];
    if (is_joint_row(row)) continue;
    Contact& c = data.contacts[static_cast<size_t>(row.contact)];
    const int k = row.kind == Row::Kind::normal ? 0 : (row.kind == Row::Kind::friction1 ? 1 : 2);
    c.impulse(k) = row.lambda;
  }
  for (int i = 0; i < data.ncon; ++i) {
    Contact& c = data.contacts[static_cast<size_t>(i)];
    c.force_world = (c.impulse.x() * c.normal + c.impulse.y() * c.tangent1 + c.impulse.z() * c.tangent2) / dt;
    data.prev_contacts[static_cast<size_t>(i)] = c;
  }
  data.prev_ncon = data.ncon;
}

}  // namespace tonus::sim::detail
