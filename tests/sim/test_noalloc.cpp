// The step allocates nothing: every malloc family call and every operator
// new made by our code is counted (tests/support/allocation_counter) over 10,000 steps of the humanoid on the
// ground with objects being thrown at it, added and removed between steps.
#include <doctest/doctest.h>

#include "support/allocation_counter.hpp"
#include "tonus/sim/humanoid.hpp"
#include "tonus/sim/objects.hpp"
#include "tonus/sim/step.hpp"

// Debug builds must also run with Eigen's own guard (step() forbids Eigen allocations).
#if !defined(NDEBUG) && !defined(EIGEN_RUNTIME_NO_MALLOC)
#error "debug builds of the physics core must define EIGEN_RUNTIME_NO_MALLOC"
#endif

using namespace tonus::sim;

TEST_CASE("10,000 steps with contacts, drives and objects added and removed allocate nothing") {
  const BuildResult built = build_humanoid(HumanoidSpec{});
  REQUIRE(built);
  const Model& model = *built.model;
  auto data = make_data(model);
  StepInputs in = make_inputs(model);
  for (int i = 1; i < model.nbody; ++i) {
    scale_joint_gains(model, in, i, 100.0, 10.0);
  }
  ObjectSpec ball;
  ball.shape = Shape::sphere(0.05);
  ball.mass_kg = 0.4;
  ball.material.restitution = 0.5;
  ObjectSpec cube;
  cube.shape = Shape::box(Vec3::Constant(0.05));

  // Sanity: the counter sees allocations (so zero below means something).
  REQUIRE(tonus::test::probe_allocation_counter() == 2);

  int max_contacts = 0, objects_added = 0, objects_removed = 0;
  tonus::test::start_counting_allocations();
  ObjectHandle live[3];
  for (int s = 0; s < 10000; ++s) {
    if (s % 500 == 0) {
      // Throw a ball at the chest and drop a cube by the feet; drop the oldest.
      const int slot = (s / 500) % 3;
      if (live[slot].valid()) objects_removed += remove_object(*data, live[slot]) ? 1 : 0;
      ObjectSpec o = slot == 2 ? cube : ball;
      o.pos = slot == 0 ? Vec3(0.8, 0.0, 1.3) : (slot == 1 ? Vec3(0.6, 0.3, 0.3) : Vec3(0.3, -0.2, 0.4));
      o.lin_vel = slot == 0 ? Vec3(-8.0, 0.0, 1.0) : Vec3::Zero();
      live[slot] = add_object(*data, o).handle;
      objects_added += live[slot].valid() ? 1 : 0;
    }
    if (step(model, *data, in) == StepStatus::diverged) break;
    max_contacts = std::max(max_contacts, data->ncon);
  }
  const long allocations = tonus::test::stop_counting_allocations();
  MESSAGE("allocations during 10,000 steps: " << allocations << " (peak " << max_contacts << " contacts, "
                                              << objects_added << " objects added, " << objects_removed << " removed)");
  CHECK(allocations == 0);
  CHECK(data->status != StepStatus::diverged);
  CHECK(max_contacts > 8);
  CHECK(objects_added == 20);
  CHECK(objects_removed == 17);
}
