// Contacts and joint limits as velocity-level constraint rows: built from the
// contacts and the joints near their limits, then prepared for the solver
// (solver.cpp) through the sparse factor of M~ (M plus the implicit drives:
// a stiff drive resists a contact exactly as the step will integrate it).
//
// With M~ = L^T D L, a row's whitened Jacobian y = D^-1/2 L^-T J^T is non-zero
// only on the dofs of the row's path(s) to the root, and
// (J M~^-1 J^T)_rs = y_r . y_s. Each row keeps its y packed over its support;
// no matrix of row pairs is ever formed, so the cost and the memory grow
// with the number of rows, not its square. A contact on one body (J^T = S^T u,
// S the path's motion axes, u the contact's spatial direction) takes its y
// from the body's six whitened axes, y = (D^-1/2 L^-T S^T) u, computed once
// per body: a foot's four points are twelve rows but six solves.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>

#include "ltdl.hpp"
#include "row_ops.hpp"
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

void limit_row(const Model& model, Data& data, int body, const Vec3& coef, double dist) {
  const double dt = model.timestep_s;
  Row r;
  r.kind = Row::Kind::limit;
  r.limit_body = body;
  r.limit_coef = coef;
  r.support = model.body_path_dofs[static_cast<size_t>(body)];
  // Speculative while inside the range (may close the gap, not cross it);
  // Baumgarte-corrected once outside.
  r.target = dist > 0.0 ? -dist / dt : -model.solver.baumgarte * dist / dt;
  if (data.njoint_rows >= static_cast<int>(kMaxJointRows) || !jacobian_fits(data, r.support, 1, kRowJacobianPool) ||
      !add_row(data, r)) {
    ++data.diag.limit_overflow;
    return;
  }
  ++data.njoint_rows;
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

bool is_object(const ContactSide& s) { return s.kind == ContactSide::Kind::object; }

// The body of a contact row with one side on the articulation (the other on
// the ground or an object), whose support is that body's path; else -1.
int single_body(const Row& row) {
  if (is_joint_row(row)) return -1;
  const bool a = row.a.kind == ContactSide::Kind::body, b = row.b.kind == ContactSide::Kind::body;
  if (a == b) return -1;
  return a ? row.a.index : row.b.index;
}

// A body's six whitened spatial axes: W[a] = D^-1/2 L^-T S^T e_a over the
// body's path (S: the path's motion axes, cdof), packed in path order. A
// contact row on the body, of spatial direction u, is then y = sum_a u_a W[a]:
// six solves per body instead of one per row (a foot's four points are twelve
// rows), and no J^T to build.
struct BodyAxes {
  int body = -1;
  bool ok = false;  // the path is a chain (always, for a tree's body)
  ltdl::PathFactor path;
  std::array<std::array<double, kMaxDofs>, 6> w;
  Vec6 v_pre = Vec6::Zero(), v_free = Vec6::Zero();  // the body's twist (world, at the origin) now and free

  // Writes the row's packed y and returns |y|^2.
  double whiten(const Vec6& u, double* values, std::uint8_t* dofs) const {
    // One pass per dof, the six axes summed in order in a register.
    const auto n = static_cast<size_t>(path.size);
    const double u0 = u(0), u1 = u(1), u2 = u(2), u3 = u(3), u4 = u(4), u5 = u(5);
    double norm2 = 0.0;
    for (size_t j = 0; j < n; ++j) {
      const double y = u0 * w[0][j] + u1 * w[1][j] + u2 * w[2][j] + u3 * w[3][j] + u4 * w[4][j] + u5 * w[5][j];
      values[j] = y;
      dofs[j] = path.dofs[j];
      norm2 += y * y;
    }
    return norm2;
  }
};

void load_axes(const Model& model, const Data& data, int body, const std::array<double, kMaxDofs>& inv_sqrt_d,
               BodyAxes& axes) {
  axes.body = body;
  const int nv = model.nv, first = data.first_active_dof;
  axes.ok = ltdl::gather_path(data.factor, nv, model.dof_parent, first, model.body_path_dofs[static_cast<size_t>(body)],
                              axes.path);
  if (!axes.ok) return;
  const ltdl::PathFactor& p = axes.path;
  const auto begin = static_cast<size_t>(p.begin), n = static_cast<size_t>(p.size);
  axes.v_pre.setZero();
  axes.v_free.setZero();
  for (size_t j = 0; j < n; ++j) {
    const auto k = static_cast<size_t>(p.dofs[j]);
    axes.v_pre += data.cdof[k] * data.qvel[k];
    axes.v_free += data.cdof[k] * data.qvel_free[k];
  }
  // The six L^-T solves together (solve_lt_path's order, six right-hand
  // sides side by side): each entry of L is read once for all six.
  std::array<Vec6, kMaxDofs> x;
  for (size_t j = begin; j < n; ++j) x[j] = data.cdof[p.dofs[j]];
  for (size_t j = n; j-- > begin;) {
    const Vec6 xj = x[j];
    const double* lj = &p.l[j * kMaxDofs];
    for (size_t i = begin; i < j; ++i) x[i] -= lj[i] * xj;
  }
  for (size_t a = 0; a < 6; ++a) {
    const auto ai = static_cast<Eigen::Index>(a);
    // Prescribed dofs do not yield.
    for (size_t j = 0; j < begin; ++j) axes.w[a][j] = 0.0;
    for (size_t j = begin; j < n; ++j) axes.w[a][j] = x[j](ai) * inv_sqrt_d[p.dofs[j]];
  }
}

// Any other row (a joint's, or a contact between two bodies): J^T on the
// support, then the L^-T solve. Returns |y|^2 and adds J qvel to v_pre and v_free.
double whiten_row(const Model& model, Data& data, const Row& row, const std::array<double, kMaxDofs>& inv_sqrt_d,
                  ltdl::PathFactor& path, double& v_pre, double& v_free) {
  const int nv = model.nv, first = data.first_active_dof;
  const auto unv = static_cast<size_t>(nv);
  std::array<double, kMaxDofs> y;
  for (std::uint64_t bits = row.support; bits != 0; bits &= bits - 1)
    y[static_cast<size_t>(std::countr_zero(bits))] = 0.0;
  if (is_joint_row(row)) {
    const Body& b = model.bodies[static_cast<size_t>(row.limit_body)];
    for (int k = 0; k < b.dof_num; ++k) y[static_cast<size_t>(b.dof_adr) + static_cast<size_t>(k)] = row.limit_coef(k);
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
  for (std::uint64_t bits = row.support; bits != 0; bits &= bits - 1) {
    const auto k = static_cast<size_t>(std::countr_zero(bits));
    v_pre += y[k] * data.qvel[k];
    v_free += y[k] * data.qvel_free[k];
  }
  // Prescribed dofs do not yield; the solve stays on the support (L has the tree's sparsity).
  for (std::uint64_t bits = row.support; bits != 0; bits &= bits - 1) {
    const auto k = static_cast<size_t>(std::countr_zero(bits));
    if (static_cast<int>(k) < first) y[k] = 0.0;
  }
  if (row.support != path.support && !ltdl::gather_path(data.factor, nv, model.dof_parent, first, row.support, path)) {
    ltdl::solve_lt_on(data.factor, nv, model.dof_parent, first, row.support, std::span<double>(y).first(unv));
  } else {
    ltdl::solve_lt_path(path, std::span<double>(y).first(unv));
  }
  double norm2 = 0.0;
  auto at = static_cast<size_t>(row.jac_offset);
  for (std::uint64_t bits = row.support; bits != 0; bits &= bits - 1, ++at) {
    const auto k = static_cast<size_t>(std::countr_zero(bits));
    const double yk = static_cast<int>(k) >= first ? y[k] * inv_sqrt_d[k] : 0.0;
    data.jac_values[at] = yk;
    data.jac_dofs[at] = static_cast<std::uint8_t>(k);
    norm2 += yk * yk;
  }
  return norm2;
}

}  // namespace

void build_rows(const Model& model, Data& data) {
  data.nrows = 0;
  data.njoint_rows = 0;
  data.jac_used = 0;
  constexpr std::size_t kContactPool = kRowJacobianPool - kJointRowPoolReserve;
  for (int ci = 0; ci < data.ncon; ++ci) {
    const Contact& c = data.contacts[static_cast<size_t>(ci)];
    const std::uint64_t support = side_support(model, c.a) | side_support(model, c.b);
    const Vec3 dirs[3] = {c.normal, c.tangent1, c.tangent2};
    const int nrow = c.friction > 0.0 ? 3 : 1;
    if (data.nrows + nrow > static_cast<int>(kMaxRows - kMaxJointRows) ||
        !jacobian_fits(data, support, nrow, kContactPool)) {
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
  data.jac_base_used = data.jac_used;
}

void assemble_rows(const Model& model, Data& data) {
  const int nv = model.nv;
  const int first = data.first_active_dof;
  const auto unv = static_cast<size_t>(nv);
  const auto n = static_cast<size_t>(data.nrows);
  std::array<double, kMaxDofs> inv_sqrt_d;
  for (int k = first; k < nv; ++k) {
    const auto ku = static_cast<size_t>(k);
    inv_sqrt_d[ku] = 1.0 / std::sqrt(data.factor[ku * unv + ku]);
  }
  std::fill_n(data.solve_w.begin(), unv, 0.0);
  data.obj_dlin.fill(Vec3::Zero());
  data.obj_dang.fill(Vec3::Zero());

  // The last body's axes and the last path gathered: rows on one body come together.
  BodyAxes axes;
  ltdl::PathFactor path;
  for (size_t r = 0; r < n; ++r) {
    Row& row = data.rows[r];
    double v_pre = side_velocity(data, row.a, row.ua, false) + side_velocity(data, row.b, row.ub, false);
    double v_free = side_velocity(data, row.a, row.ua, true) + side_velocity(data, row.b, row.ub, true);
    double diag = 0.0;
    const int body = single_body(row);
    if (body >= 0 && axes.body != body) load_axes(model, data, body, inv_sqrt_d, axes);
    if (body >= 0 && axes.ok) {
      const Vec6& u = row.a.kind == ContactSide::Kind::body ? row.ua : row.ub;
      v_pre += u.dot(axes.v_pre);
      v_free += u.dot(axes.v_free);
      diag += axes.whiten(u, &data.jac_values[static_cast<size_t>(row.jac_offset)],
                          &data.jac_dofs[static_cast<size_t>(row.jac_offset)]);
    } else if (row.jac_size > 0) {
      diag += whiten_row(model, data, row, inv_sqrt_d, path, v_pre, v_free);
    }
    row.ia.setZero();
    row.ib.setZero();
    row.inv_mass_a = row.inv_mass_b = 0.0;
    if (!is_joint_row(row)) {
      if (is_object(row.a)) {
        const auto i = static_cast<size_t>(row.a.index);
        row.ia = data.obj_inv_inertia[i] * row.ua.head<3>();
        row.inv_mass_a = 1.0 / data.objects[i].mass_kg;
        diag += row.ua.head<3>().dot(row.ia) + row.ua.tail<3>().squaredNorm() * row.inv_mass_a;
      }
      if (is_object(row.b)) {
        const auto i = static_cast<size_t>(row.b.index);
        row.ib = data.obj_inv_inertia[i] * row.ub.head<3>();
        row.inv_mass_b = 1.0 / data.objects[i].mass_kg;
        diag += row.ub.head<3>().dot(row.ib) + row.ub.tail<3>().squaredNorm() * row.inv_mass_b;
      }
    }
    row.diag = diag;
    if (is_unilateral(row)) row.bound = diag > kRowMinDiag ? kMaxRowSpeedChange / diag : 0.0;
    row.pre = v_pre;
    row.v0 = v_free;
    if (!(diag > kRowMinDiag)) row.lambda = 0.0;  // nothing can move along it (e.g. a kinematic body on the ground)
    if (row.lambda != 0.0) apply_row_impulse(data, row, row.lambda);  // the warm start
  }

  // Normal-row targets: restitution on real impacts, otherwise close the gap
  // without overshooting (speculative) or push a penetration out (Baumgarte).
  const double dt = model.timestep_s;
  for (size_t r = 0; r < n; ++r) {
    Row& row = data.rows[r];
    if (row.kind != Row::Kind::normal) continue;
    const Contact& c = data.contacts[static_cast<size_t>(row.contact)];
    const double approach = row.pre;
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
  }
  remember_contacts(data);
}

}  // namespace tonus::sim::detail
