// The constraint solve: projected Gauss-Seidel on the rows, island by island,
// each to a velocity-level residual.
//
// Islands: rows that share no moving body cannot influence each other, so the
// rows are split into independent groups (union-find over the articulation
// and the objects; the ground joins nothing) and each group is solved on its
// own and stops on its own: a ball at rest on the floor is done in a sweep
// while a pile still settles. Within a group, rows are swept in their build
// order (a contact's friction follows its normal row), so a step is
// deterministic.
//
// A row's velocity is read through the running impulse sums (row_ops.hpp), so
// a sweep costs the sum of the rows' sizes: linear in the number of rows.
//
// Convergence: the residual of a row is the velocity-level complementarity
// error at the current impulses (the change in velocity one more projected
// update of that row alone would make: |v - target| for a pushing normal row,
// the closing speed of one that does not push, the slip of sticking friction
// or the misalignment of sliding friction at the cone). A group stops when a
// sweep changes no row by more than the tolerance and a pass that changes
// nothing confirms every row is within it; the step reports the largest
// residual left.
#include <algorithm>
#include <bit>
#include <bitset>
#include <cmath>
#include <cstddef>

#include "ltdl.hpp"
#include "row_ops.hpp"
#include "stages.hpp"

namespace tonus::sim::detail {
namespace {

using std::size_t;
using Row = Data::Row;

int find_root(Data& data, int node) {
  auto& parent = data.island_parent;
  while (parent[static_cast<size_t>(node)] != node) {
    parent[static_cast<size_t>(node)] = parent[static_cast<size_t>(parent[static_cast<size_t>(node)])];
    node = parent[static_cast<size_t>(node)];
  }
  return node;
}

void join(Data& data, int x, int y) {
  x = find_root(data, x);
  y = find_root(data, y);
  if (x == y) return;
  // The lower node stays the root: the articulation (node 0) roots its island.
  if (x < y) {
    data.island_parent[static_cast<size_t>(y)] = x;
  } else {
    data.island_parent[static_cast<size_t>(x)] = y;
  }
}

int side_node(const ContactSide& s) {
  switch (s.kind) {
    case ContactSide::Kind::body: return 0;
    case ContactSide::Kind::object: return s.index + 1;
    case ContactSide::Kind::ground: return -1;
  }
  return -1;
}

// Partitions the rows into islands, keeping their order within each.
void build_islands(Data& data) {
  const auto n = static_cast<size_t>(data.nrows);
  constexpr size_t kNodes = kMaxObjects + 1;
  for (size_t i = 0; i < kNodes; ++i) data.island_parent[i] = static_cast<int>(i);
  for (size_t r = 0; r < n; ++r) {
    const Row& row = data.rows[r];
    if (is_joint_row(row)) continue;  // on the articulation alone
    const int a = side_node(row.a), b = side_node(row.b);
    if (a >= 0 && b >= 0) join(data, a, b);
  }
  // Number the islands that have rows, in order of their first row.
  std::array<int, kNodes> number{};
  number.fill(-1);
  std::array<int, kNodes + 1> count{};
  int islands = 0;
  for (size_t r = 0; r < n; ++r) {
    Row& row = data.rows[r];
    const int node = is_joint_row(row) ? 0 : std::max(side_node(row.a), side_node(row.b));
    const auto root = static_cast<size_t>(find_root(data, node));
    if (number[root] < 0) number[root] = islands++;
    row.island = number[root];
    ++count[static_cast<size_t>(row.island)];
  }
  data.nislands = islands;
  data.island_start[0] = 0;
  for (size_t s = 0; s < static_cast<size_t>(islands); ++s) data.island_start[s + 1] = data.island_start[s] + count[s];
  std::array<int, kNodes + 1> fill{};
  std::copy_n(data.island_start.begin(), islands, fill.begin());
  for (size_t r = 0; r < n; ++r) {
    const auto s = static_cast<size_t>(data.rows[r].island);
    data.island_rows[static_cast<size_t>(fill[s]++)] = static_cast<int>(r);
  }
}

// One projected update of the unit (a row, a contact's friction pair, a
// drive's group) starting at island_rows[p]. Returns the largest velocity
// change it makes (or would make, when !apply) and the number of rows it spans.
struct UnitResult {
  double residual = 0.0;
  int rows = 1;
};

UnitResult update_unit(Data& data, int first_row, bool apply) {
  const auto r = static_cast<size_t>(first_row);
  Row& row = data.rows[r];
  switch (row.kind) {
    case Row::Kind::normal:
    case Row::Kind::limit: {
      if (!(row.diag > kRowMinDiag)) return {};
      const double next = std::clamp(row.lambda + (row.target - row_velocity(data, row)) / row.diag, 0.0, row.bound);
      const double delta = next - row.lambda;
      if (apply && delta != 0.0) {
        apply_row_impulse(data, row, delta);
        row.lambda = next;
      }
      return {std::abs(delta) * row.diag, 1};
    }
    case Row::Kind::friction1: {
      // Both tangent rows, then the projection onto the Coulomb disc of the
      // contact's normal impulse (the row before).
      Row& row2 = data.rows[r + 1];
      const double a11 = row.diag, a22 = row2.diag;
      double l1 = 0.0, l2 = 0.0;
      if (a11 > kRowMinDiag) l1 = row.lambda - row_velocity(data, row) / a11;
      if (a22 > kRowMinDiag) l2 = row2.lambda - row_velocity(data, row2) / a22;
      const Contact& c = data.contacts[static_cast<size_t>(row.contact)];
      const double cap = c.friction * std::max(0.0, data.rows[r - 1].lambda);
      const double norm = std::sqrt(l1 * l1 + l2 * l2);
      const double scale = norm > cap ? (norm > 0.0 ? cap / norm : 0.0) : 1.0;
      l1 *= scale;
      l2 *= scale;
      const double d1 = l1 - row.lambda, d2 = l2 - row2.lambda;
      if (apply) {
        if (d1 != 0.0) apply_row_impulse(data, row, d1);
        if (d2 != 0.0) apply_row_impulse(data, row2, d2);
        row.lambda = l1;
        row2.lambda = l2;
      }
      return {std::max(std::abs(d1) * a11, std::abs(d2) * a22), 2};
    }
    case Row::Kind::drive: {
      // A drive's rows (one per dof of the joint), each a compliant target,
      // then the group's torque bounded as a vector.
      const size_t last = drive_group_end(data, r) - 1;
      double norm2 = 0.0;
      std::array<double, 3> next{};
      for (size_t k = r; k <= last; ++k) {
        const Row& rk = data.rows[k];
        const double akk = rk.diag + rk.cfm;
        next[k - r] = rk.lambda + (rk.target - row_velocity(data, rk) - rk.cfm * rk.lambda) / akk;
        norm2 += next[k - r] * next[k - r];
      }
      const double norm = std::sqrt(norm2);
      const double scale = norm > row.bound ? row.bound / norm : 1.0;
      double residual = 0.0;
      for (size_t k = r; k <= last; ++k) {
        Row& rk = data.rows[k];
        const double l = next[k - r] * scale;
        residual = std::max(residual, std::abs(l - rk.lambda) * (rk.diag + rk.cfm));
        if (apply && l != rk.lambda) {
          apply_row_impulse(data, rk, l - rk.lambda);
          rk.lambda = l;
        }
      }
      return {residual, static_cast<int>(last - r + 1)};
    }
    case Row::Kind::friction2: return {};  // with friction1
  }
  return {};
}

// One pass over an island's rows. With apply, a Gauss-Seidel sweep returning
// the largest change made; without, the residual at the current impulses.
double pass(Data& data, int begin, int end, bool apply, std::uint64_t& updates) {
  double largest = 0.0;
  for (int p = begin; p < end;) {
    const UnitResult u = update_unit(data, data.island_rows[static_cast<size_t>(p)], apply);
    largest = std::max(largest, u.residual);
    p += u.rows;
    updates += static_cast<std::uint64_t>(u.rows);
  }
  return largest;
}

// Keeps each island row's impulse in solve_before (the change of a sweep, a step to take back).
void save_impulses(Data& data, int begin, int end) {
  for (int p = begin; p < end; ++p) {
    const auto r = static_cast<size_t>(data.island_rows[static_cast<size_t>(p)]);
    data.solve_before[r] = data.rows[r].lambda;
  }
}

// Back to impulses kept earlier: save_impulses()'s (solve_before) or a
// subspace step's checkpoint (solve_checkpoint).
void restore_impulses(Data& data, int begin, int end, const std::array<double, kMaxRows>& saved) {
  for (int p = begin; p < end; ++p) {
    const auto r = static_cast<size_t>(data.island_rows[static_cast<size_t>(p)]);
    Row& row = data.rows[r];
    const double back = saved[r] - row.lambda;
    if (back == 0.0) continue;
    apply_row_impulse(data, row, back);
    row.lambda = saved[r];
  }
}

// Nonsmooth nonlinear conjugate gradients (Silcowitz, Niebe, Erleben 2010):
// a projected Gauss-Seidel sweep is a descent step, and its change g is
// taken as the negative gradient; adding beta times the previous direction,
// beta = |g_k|^2 / |g_k-1|^2 (Fletcher-Reeves), with a restart whenever the
// change grows. Redundant contacts on one body (sixteen points under two
// feet) and heavy-light pairs (a ball on a 70 kg avatar) make plain sweeps
// crawl; the momentum crosses those valleys in a few times fewer sweeps at
// the cost of one more pass over the impulses. Impulses after a momentum
// step may leave their cones; the next sweep projects them, and the solve
// always ends on a sweep, so its impulses are feasible.
void momentum(Data& data, int begin, int end, double& gg_prev, bool& have_dir) {
  double gg = 0.0;
  for (int p = begin; p < end; ++p) {
    const auto r = static_cast<size_t>(data.island_rows[static_cast<size_t>(p)]);
    const double g = data.rows[r].lambda - data.solve_before[r];
    gg += g * g;
  }
  const double beta = have_dir && gg_prev > 0.0 ? gg / gg_prev : 0.0;
  const bool restart = !(beta <= 1.0);
  for (int p = begin; p < end; ++p) {
    const auto r = static_cast<size_t>(data.island_rows[static_cast<size_t>(p)]);
    Row& row = data.rows[r];
    const double g = row.lambda - data.solve_before[r];
    if (restart) {
      data.solve_dir[r] = g;
      continue;
    }
    // A row the sweep holds at zero gets no momentum: pushed below zero, the
    // next sweep clips it back by as much, the change stays the same, beta
    // stays 1, and the pair cycles forever (a toe resting on the floor did,
    // for hundreds of steps, at 1.6e-6 m/s).
    const bool at_zero = is_unilateral(row) && row.lambda <= 0.0;
    const double step = at_zero ? 0.0 : beta * data.solve_dir[r];
    if (step != 0.0) {
      apply_row_impulse(data, row, step);
      row.lambda += step;
    }
    data.solve_dir[r] = step + g;
  }
  gg_prev = gg;
  have_dir = true;
}

// The subspace step (Silcowitz, Niebe, Erleben 2009, "projected Gauss-Seidel
// subspace minimization"): sweeps find which rows push (normals and limits
// with an impulse, friction inside its cone, drives inside their bound) long
// before they find the impulses; those rows, held as equalities, are one
// linear system (J M~^-1 J^T + compliance) dlambda = target - v, solved
// directly. Sixteen points under two feet are redundant (more rows than the
// legs have dofs): the factorisation drops the rows that depend on others.
// Sweeps then project the result and confirm the active set; a wrong guess
// only costs the sweeps that fix it.

// A pivot below this fraction of its row's own effective mass marks a
// dependent row: its part outside the kept rows is under 1e-3 of it. A foot
// point and a toe point at the toe joint are such a pair: only the joint's
// compliance tells them apart, and solving for both amplifies that (shower100
// over 20000 steps, from 1e-8: sweeps mean 13.8 -> 10.4, p99 135 -> 100,
// unconverged steps 147 -> 102). The sweeps share the load between them.
constexpr double kDependentPivot = 1e-6;

bool is_sticking(const Data& data, size_t friction1) {
  const Row& t1 = data.rows[friction1];
  const Row& t2 = data.rows[friction1 + 1];
  const double n = data.rows[friction1 - 1].lambda;
  const double mu = data.contacts[static_cast<size_t>(t1.contact)].friction;
  return n > 0.0 && std::sqrt(t1.lambda * t1.lambda + t2.lambda * t2.lambda) < mu * n * (1.0 - 1e-9);
}

bool is_active(const Data& data, size_t r) {
  const Row& row = data.rows[r];
  if (!(row.diag > kRowMinDiag)) return false;
  switch (row.kind) {
    case Row::Kind::normal:
    case Row::Kind::limit: return row.lambda > 0.0 && row.lambda < row.bound;
    case Row::Kind::friction1: return is_sticking(data, r);
    case Row::Kind::friction2: return is_sticking(data, r - 1);
    case Row::Kind::drive: {
      double norm2 = 0.0;
      const auto first = static_cast<size_t>(row.group);
      for (size_t k = first, end = drive_group_end(data, first); k < end; ++k)
        norm2 += data.rows[k].lambda * data.rows[k].lambda;
      return std::sqrt(norm2) < row.bound * (1.0 - 1e-9);
    }
  }
  return false;
}

// u_r^T M_o^-1 u_s over the objects rows r and s share.
double object_coupling(const Row& r, const Row& s) {
  double a = 0.0;
  const auto term = [&](const ContactSide& side_r, const Vec6& ur, const Vec3& ir, double inv_m) {
    if (inv_m <= 0.0) return;
    if (s.inv_mass_a > 0.0 && s.a.index == side_r.index)
      a += s.ua.head<3>().dot(ir) + inv_m * s.ua.tail<3>().dot(ur.tail<3>());
    if (s.inv_mass_b > 0.0 && s.b.index == side_r.index)
      a += s.ub.head<3>().dot(ir) + inv_m * s.ub.tail<3>().dot(ur.tail<3>());
  };
  term(r.a, r.ua, r.ia, r.inv_mass_a);
  term(r.b, r.ub, r.ib, r.inv_mass_b);
  return a;
}

// Dense dot product through Eigen (vectorised, in Eigen's fixed order).
double dot(const double* x, const double* y, size_t n) {
  if (n == 0) return 0.0;
  const auto len = static_cast<Eigen::Index>(n);
  return Eigen::Map<const Eigen::VectorXd>(x, len).dot(Eigen::Map<const Eigen::VectorXd>(y, len));
}

// Two rows' shared dofs, when they are the lowest dofs of both supports (a
// row's support is its bodies' paths to the root, dofs numbered root first,
// so two single-path rows share the path to their common ancestor, which
// leads both packed rows): their number. -1 when they share dofs otherwise.
int shared_prefix(std::uint64_t a, std::uint64_t b) {
  const std::uint64_t both = a & b;
  if (both == 0) return 0;
  const auto top = static_cast<unsigned>(63 - std::countl_zero(both));
  const std::uint64_t below = top == 63 ? ~std::uint64_t{0} : (std::uint64_t{2} << top) - 1;
  if ((a & below) != both || (b & below) != both) return -1;
  return bit_count(both);
}

// Adds (sign = 1) or takes back (sign = -1) the subspace step's change.
void apply_subspace(Data& data, size_t m, double sign) {
  for (size_t i = 0; i < m; ++i) {
    Row& row = data.rows[static_cast<size_t>(data.subspace_rows[i])];
    const double delta = sign * data.subspace_rhs[i];
    if (delta == 0.0) continue;
    apply_row_impulse(data, row, delta);
    row.lambda += delta;
  }
}

// (J M~^-1 J^T + compliance)_ik of two rows, through their packed whitened
// rows; `dense` holds row i's scattered over the dofs.
double subspace_entry(const Data& data, const Row& ri, const Row& rk, const std::array<double, kMaxDofs>& dense,
                      int shared) {
  const auto oi = static_cast<size_t>(std::max(ri.jac_offset, 0));
  const auto ok = static_cast<size_t>(std::max(rk.jac_offset, 0));
  double v = 0.0;
  if (shared >= 0) {
    // The shared dofs lead both packed rows: a contiguous dot product.
    v = dot(&data.jac_values[ok], &data.jac_values[oi], static_cast<size_t>(shared));
  } else {
    for (size_t j = 0; j < static_cast<size_t>(rk.jac_size); ++j)
      v += data.jac_values[ok + j] * dense[data.jac_dofs[ok + j]];
  }
  if (ri.inv_mass_a > 0.0 || ri.inv_mass_b > 0.0) v += object_coupling(ri, rk);
  return v;
}

// The body a contact with the ground acts on, else -1. All its rows' whitened
// Jacobians lie in the span of the body's six whitened axes (constraints.cpp),
// so no more of them than that span's dimension are independent.
int grounded_body(const Row& row) {
  if (is_joint_row(row)) return -1;
  if (row.a.kind == ContactSide::Kind::body && row.b.kind == ContactSide::Kind::ground) return row.a.index;
  if (row.b.kind == ContactSide::Kind::body && row.a.kind == ContactSide::Kind::ground) return row.b.index;
  return -1;
}

// Factorises and solves the system of the island's active rows but those
// released. Returns false when there was nothing to do or no room (the island
// keeps sweeping). Leaves the step in subspace_rhs for its first m rows.
//
// The factorisation is up-looking: each active row in turn is dotted with
// the rows kept so far, a forward solve gives its row of L, and a pivot that
// vanishes marks a row that depends on the kept ones. Sixteen points under
// two feet are three times the rows a rigid foot has dofs for; a dependent
// row is left out of the system before it costs a row of the matrix, so the
// work follows the kept rows (at most the island's dofs), not the active ones.
// A body on the ground whose kept rows already span its whitened axes needs
// no test at all. A row left out keeps its impulse, so the others meet their
// targets exactly and nothing is amplified.
bool subspace_factor_solve(Data& data, int begin, int end, const std::bitset<kMaxRows>& released, size_t& m_out) {
  constexpr size_t kStride = kSubspaceRows;
  double* l = data.subspace_matrix.data();  // row i of L at l + i * kStride
  double* b = data.subspace_rhs.data();
  std::array<double, kMaxDofs> dense{};
  std::array<std::uint8_t, kMaxBodies> kept_on_body{};
  const auto first = static_cast<unsigned>(data.first_active_dof);
  const std::uint64_t free_dofs = first >= 64 ? 0 : ~((std::uint64_t{1} << first) - 1);  // prescribed dofs span nothing
  size_t m = 0;
  for (int p = begin; p < end; ++p) {
    const auto r = static_cast<size_t>(data.island_rows[static_cast<size_t>(p)]);
    if (released[r] || !is_active(data, r)) continue;
    const Row& ri = data.rows[r];
    const int body = grounded_body(ri);
    const auto span = static_cast<std::uint8_t>(std::min(6, bit_count(ri.support & free_dofs)));
    if (body >= 0 && kept_on_body[static_cast<size_t>(body)] >= span) continue;  // depends on the kept rows
    if (m == kSubspaceRows) return false;
    const auto oi = static_cast<size_t>(std::max(ri.jac_offset, 0));
    for (size_t j = 0; j < static_cast<size_t>(ri.jac_size); ++j)
      dense[data.jac_dofs[oi + j]] = data.jac_values[oi + j];
    double* li = l + m * kStride;
    std::uint64_t seen_support = 0;
    int seen_shared = 0;
    double norm2 = 0.0;
    for (size_t k = 0; k < m; ++k) {
      const Row& rk = data.rows[static_cast<size_t>(data.subspace_rows[k])];
      if (rk.support != seen_support) {  // rows of one body come together and share their support
        seen_support = rk.support;
        seen_shared = shared_prefix(ri.support, rk.support);
      }
      const double a = subspace_entry(data, ri, rk, dense, seen_shared);
      const double lk = (a - dot(li, l + k * kStride, k)) / l[k * kStride + k];
      li[k] = lk;
      norm2 += lk * lk;
    }
    const double own = subspace_entry(data, ri, ri, dense, shared_prefix(ri.support, ri.support)) + ri.cfm;
    for (size_t j = 0; j < static_cast<size_t>(ri.jac_size); ++j) dense[data.jac_dofs[oi + j]] = 0.0;
    const double d = own - norm2;
    if (!(d > kDependentPivot * own) || !(own > 0.0)) continue;  // depends on the kept rows
    li[m] = std::sqrt(d);
    const double target = ri.kind == Row::Kind::friction1 || ri.kind == Row::Kind::friction2 ? 0.0 : ri.target;
    b[m] = target - row_velocity(data, ri) - ri.cfm * ri.lambda;
    data.subspace_rows[m++] = static_cast<int>(r);
    if (body >= 0) ++kept_on_body[static_cast<size_t>(body)];
  }
  if (m == 0) return false;
  m_out = m;
  // L L^T x = b: forward, then backward by columns (rows of L are contiguous).
  for (size_t i = 0; i < m; ++i) b[i] = (b[i] - dot(l + i * kStride, b, i)) / l[i * kStride + i];
  for (size_t i = m; i-- > 0;) {
    const double* li = l + i * kStride;
    b[i] /= li[i];
    for (size_t k = 0; k < i; ++k) b[k] -= li[k] * b[i];
  }
  for (size_t i = 0; i < m; ++i) {
    if (!std::isfinite(b[i])) return false;
  }
  return true;
}

// The active set the sweeps found, refined: a normal or limit row whose
// equality answer would pull (a negative impulse) is released, with its
// contact's friction, and the rest solved again. A toe resting on the floor
// at 1e-8 m keeps a tiny impulse for many sweeps before they find it should
// have none; taking it out here halves the lively scene's p99 of sweeps.
constexpr int kSubspaceSolves = 3;

bool subspace_solve(Data& data, int begin, int end, size_t& m) {
  std::bitset<kMaxRows> released;
  for (int solve = 0; solve < kSubspaceSolves; ++solve) {
    if (!subspace_factor_solve(data, begin, end, released, m)) return false;
    bool pulls = false;
    for (size_t i = 0; i < m; ++i) {
      const auto r = static_cast<size_t>(data.subspace_rows[i]);
      const Row& row = data.rows[r];
      if (!is_unilateral(row)) continue;
      if (row.lambda + data.subspace_rhs[i] >= 0.0) continue;
      pulls = true;
      released.set(r);
      if (row.kind != Row::Kind::normal) continue;
      // Its contact's friction rows follow it.
      for (size_t k = r + 1; k < static_cast<size_t>(data.nrows) && data.rows[k].contact == row.contact; ++k)
        released.set(k);
    }
    if (!pulls) break;
  }
  apply_subspace(data, m, 1.0);
  return true;
}

// The subspace step, kept when it lowers the island's residual: targets that
// no rigid motion meets (four penetration depths under one face) have no exact
// solution, and the step's least-squares answer can be far worse than the
// sweeps' complementary one.
//
// A step that leaves the residual higher, but by less than kTrialFactor, is
// kept on trial (a watchdog, as in nonmonotone line searches: Chamberlain et
// al. 1982): the impulses before it are kept in solve_checkpoint, and if the
// sweeps that follow have not brought the residual below the one it started
// from by the next subspace point, the island goes back to them and the step
// counts as a miss. Measured one sweep after the step, the residual is
// dominated by a few light rows (a toe's contact points, effective mass 1/11
// kg, that the step's new load on the foot leaves slipping); the sweeps settle
// those quickly, while the step has already moved the rest of the island most
// of the way. Rejected outright, such steps made shower100 crawl on momentum
// alone: over 40,000 steps, sweeps mean 10.3 -> 3.8, p99 104 -> 24 and
// unconverged steps 226 -> 44 with the trial (lively, 60,000 steps: mean 1.63
// -> 1.51, p99.9 35 -> 23, unconverged 11 -> 5). A trial costs at most the
// sweeps to the next subspace point. Steps that leave the residual more than
// kTrialFactor higher almost never pay: with every step on trial, lively had
// about 300 unconverged steps.
enum class SubspaceOutcome : std::uint8_t { rejected, accepted, on_trial };
constexpr double kTrialFactor = 30.0;

// `before` is the island's residual now; unless rejected, `after` is the residual it leaves.
SubspaceOutcome subspace_step(Data& data, int begin, int end, double before, double& after, std::uint64_t& updates) {
  save_impulses(data, begin, end);
  size_t m = 0;
  if (!subspace_solve(data, begin, end, m)) return SubspaceOutcome::rejected;
  pass(data, begin, end, true, updates);  // projects the step back into the cones
  after = pass(data, begin, end, false, updates);
  if (after < before) return SubspaceOutcome::accepted;
  if (after < kTrialFactor * before) {
    for (int p = begin; p < end; ++p) {
      const auto r = static_cast<size_t>(data.island_rows[static_cast<size_t>(p)]);
      data.solve_checkpoint[r] = data.solve_before[r];
    }
    return SubspaceOutcome::on_trial;
  }
  restore_impulses(data, begin, end, data.solve_before);
  return SubspaceOutcome::rejected;
}

// Sweeps before the first subspace step and between later ones. Most islands
// converge in one sweep from the warm start; one still moving after it (a
// standing avatar rocking on its toes, balls landing) crawls for eight or
// more, and a subspace step right away saves most of them (lively scene:
// 9.1 sweeps a step with the first step after 8, 2.9 after 1; shower100's
// p99 200 to about 100).
constexpr int kSubspaceFirst = 1;
constexpr int kSubspaceEvery = 8;
constexpr int kSubspaceMisses = 3;  // then the island only sweeps

}  // namespace

void solve_rows(const Model& model, Data& data) {
  const SolverOptions& opt = model.solver;
  build_islands(data);
  int most_sweeps = 0;
  double worst = 0.0;
  bool unconverged = false;
  std::uint64_t updates = 0;
  for (size_t s = 0; s < static_cast<size_t>(data.nislands); ++s) {
    const int begin = data.island_start[s], end = data.island_start[s + 1];
    int sweeps = 0;
    double residual = 0.0;
    bool done = false;
    double gg_prev = 0.0;
    bool have_dir = false;
    int subspace_misses = 0;
    bool on_trial = false;        // a subspace step is on trial (see subspace_step)
    double trial_residual = 0.0;  // the residual at the checkpoint it may return to
    while (sweeps < opt.iterations) {
      save_impulses(data, begin, end);
      const double change = pass(data, begin, end, true, updates);
      ++sweeps;
      // The residual is measured when a sweep changed little, and at every
      // subspace point even when it did not: under momentum a sweep keeps
      // taking back the push before it, so its change can sit above the
      // tolerance for good while the residual is already within it (shower100:
      // steps ran all 200 sweeps and ended at 6e-7).
      const bool subspace_point = sweeps == kSubspaceFirst || sweeps % kSubspaceEvery == 0;
      if (change <= opt.tolerance || subspace_point) {
        residual = pass(data, begin, end, false, updates);
        if (residual <= opt.tolerance) {
          done = true;
          break;
        }
      }
      if (on_trial && subspace_point) {
        on_trial = false;
        if (!(residual < trial_residual)) {  // the step on trial did not pay: back to before it
          restore_impulses(data, begin, end, data.solve_checkpoint);
          residual = trial_residual;
          have_dir = false;
          ++subspace_misses;
          continue;
        }
      }
      if (sweeps >= opt.iterations) break;
      if (subspace_point && subspace_misses < kSubspaceMisses) {
        double after = 0.0;
        const SubspaceOutcome outcome = subspace_step(data, begin, end, residual, after, updates);
        if (outcome != SubspaceOutcome::rejected) {
          if (after <= opt.tolerance) {  // the step's own pass ended on a sweep: confirmed
            residual = after;
            done = true;
            break;
          }
          on_trial = outcome == SubspaceOutcome::on_trial;
          trial_residual = residual;
          residual = after;
          have_dir = false;  // the direction belonged to the sweeps before
          continue;
        }
        ++subspace_misses;  // it did not help this time
      }
      momentum(data, begin, end, gg_prev, have_dir);
    }
    if (!done) {
      residual = pass(data, begin, end, false, updates);
      if (on_trial && !(residual < trial_residual)) {  // out of sweeps with a step on trial that did not pay
        restore_impulses(data, begin, end, data.solve_checkpoint);
        residual = trial_residual;
      }
      unconverged = unconverged || residual > opt.tolerance;
    }
    most_sweeps = std::max(most_sweeps, sweeps);
    worst = std::max(worst, residual);
  }
  data.diag.solver_iterations = most_sweeps;
  data.diag.solver_islands = data.nislands;
  data.diag.solver_row_updates = updates;
  data.diag.solver_residual = worst;
  if (unconverged) ++data.diag.solver_unconverged;
}

void apply_impulses(const Model& model, Data& data) {
  const int nv = model.nv;
  const int first = data.first_active_dof;
  const auto unv = static_cast<size_t>(nv);
  // dv = M~^-1 J^T lambda = L^-1 D^-1/2 (sum of y_r lambda_r).
  std::array<double, kMaxDofs> z{};
  std::copy_n(data.solve_w.begin(), unv, z.begin());
  for (int k = first; k < nv; ++k) {
    const auto ku = static_cast<size_t>(k);
    z[ku] /= std::sqrt(data.factor[ku * unv + ku]);
  }
  ltdl::solve_l(data.factor, nv, model.dof_parent, first, std::span<double>(z).first(unv));
  for (size_t k = 0; k < unv; ++k) data.qvel_next[k] = data.qvel_free[k] + (static_cast<int>(k) >= first ? z[k] : 0.0);
  for (size_t i = 0; i < kMaxObjects; ++i) {
    data.obj_lin_next[i] = data.obj_lin_free[i] + data.obj_dlin[i];
    data.obj_ang_next[i] = data.obj_ang_free[i] + data.obj_dang[i];
  }
}

}  // namespace tonus::sim::detail
