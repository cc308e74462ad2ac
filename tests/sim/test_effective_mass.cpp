// The solver's whitened rows (sim/src/constraints.cpp: per-body axes for a
// contact on one body, a per-row solve otherwise) against a dense reference:
// y_r . y_s must be (J M~^-1 J^T)_rs, with M~ = M + dt Kd + dt^2 Kp factored
// by Eigen's LDLT and J built from the dofs' motion axes.
#include <doctest/doctest.h>

#include <Eigen/Dense>
#include <cstddef>

#include "sim_fixtures.hpp"
#include "stages.hpp"

using namespace tonus::sim;

namespace {

// Runs the stages step() runs before the solve, on the current state.
void assemble_now(const Model& model, Data& data, const StepInputs& in) {
  forward_kinematics(model, data);
  mass_matrix(model, data);
  detail::objects_free_velocity(model, data);
  detail::detect_contacts(model, data);
  detail::build_rows(model, data);
  detail::drive_errors(model, data, in);
  detail::drive_terms(model, data, in.scheme);
  detail::add_drive_rows(model, data);
  REQUIRE(detail::free_velocity(model, data));
  detail::assemble_rows(model, data);
}

// Largest |y_r . y_s - (J M~^-1 J^T)_rs| over the articulation's rows, relative to the largest entry.
double worst_relative_error(const Model& model, const Data& data) {
  const int nv = model.nv, first = data.first_active_dof, na = nv - first;
  const auto unv = static_cast<std::size_t>(nv);
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(na, na);
  const double dt = model.timestep_s;
  for (int r = first; r < nv; ++r) {
    for (int c = first; c <= r; ++c) {
      const double v = data.mass[static_cast<std::size_t>(r) * unv + static_cast<std::size_t>(c)];
      m(r - first, c - first) = v;
      m(c - first, r - first) = v;
    }
    const auto k = static_cast<std::size_t>(r);
    m(r - first, r - first) += dt * data.kd_dof[k] + dt * dt * data.kp_dof[k];
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(m);
  REQUIRE(ldlt.info() == Eigen::Success);

  int rows = 0;
  Eigen::MatrixXd j(data.nrows, na), y(data.nrows, nv);
  for (int r = 0; r < data.nrows; ++r) {
    const Data::Row& row = data.rows[static_cast<std::size_t>(r)];
    if (row.jac_size <= 0 || row.kind == Data::Row::Kind::limit || row.kind == Data::Row::Kind::drive) continue;
    j.row(rows).setZero();
    y.row(rows).setZero();
    for (const auto* side : {&row.a, &row.b}) {
      if (side->kind != ContactSide::Kind::body) continue;
      const Vec6& u = side == &row.a ? row.ua : row.ub;
      for (int k = first; k < nv; ++k)
        if ((model.body_path_dofs[static_cast<std::size_t>(side->index)] >> static_cast<unsigned>(k)) & 1U)
          j(rows, k - first) += u.dot(data.cdof[static_cast<std::size_t>(k)]);
    }
    for (int e = 0; e < row.jac_size; ++e) {
      const std::size_t at = static_cast<std::size_t>(row.jac_offset) + static_cast<std::size_t>(e);
      y(rows, data.jac_dofs[at]) = data.jac_values[at];
    }
    ++rows;
  }
  REQUIRE(rows > 0);
  const Eigen::MatrixXd jr = j.topRows(rows);
  const Eigen::MatrixXd reference = jr * ldlt.solve(jr.transpose());
  const Eigen::MatrixXd ours = y.topRows(rows) * y.topRows(rows).transpose();
  MESSAGE(rows << " contact rows, first active dof " << first);
  return (ours - reference).cwiseAbs().maxCoeff() / reference.cwiseAbs().maxCoeff();
}

}  // namespace

TEST_CASE("effective mass: the whitened contact rows give J M~^-1 J^T of a dense LDLT, free and kinematic root") {
  for (const RootMode mode : {RootMode::free, RootMode::kinematic}) {
    const auto model = test::humanoid(Features{});
    auto data = make_data(*model);
    set_root_mode(*data, mode);
    StepInputs in = make_inputs(*model);
    if (mode == RootMode::kinematic) in.root_pos.z() -= 0.002;  // the feet on the floor
    // A cube on the right hand: rows on the arm's path beside the feet's.
    forward_kinematics(*model, *data);
    REQUIRE(test::add_cube_on_right_hand(*model, *data));
    for (int s = 0; s < 60; ++s) REQUIRE(step(*model, *data, in) != StepStatus::diverged);
    assemble_now(*model, *data, in);
    const double error = worst_relative_error(*model, *data);
    MESSAGE("largest relative difference " << error);
    CHECK(error < 1e-10);
  }
}
