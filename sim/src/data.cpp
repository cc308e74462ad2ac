// Data: the one allocation, and the reset to the rest configuration.
#include "tonus/sim/data.hpp"

#include <algorithm>

#include "tonus/sim/step.hpp"

namespace tonus::sim {

double Contact::normal_force_n() const { return force_world.dot(normal); }

std::unique_ptr<Data> make_data(const Model& model) {
  auto data = std::make_unique<Data>();
  reset_data(model, *data);
  return data;
}

void reset_data(const Model& model, Data& data) {
  data.time_s = 0.0;
  data.qpos = model.qpos0;
  data.qvel.fill(0.0);
  data.qacc.fill(0.0);
  data.tau_pd.fill(0.0);
  data.tau_ff.fill(0.0);
  data.drive_saturated.fill(false);
  data.drive_in_rows.fill(false);
  data.drive_impulse.fill(0.0);
  for (Object& o : data.objects) o.active = false;  // generations survive, so old handles stay stale
  data.ncon = 0;
  data.prev_ncon = 0;
  data.nrows = 0;
  data.diag = Diagnostics{};
  data.status = StepStatus::ok;
  data.root_servo_force.setZero();
  data.root_servo_torque.setZero();
  data.root_wrench_force.setZero();
  data.root_wrench_torque.setZero();
  forward_kinematics(model, data);
}

}  // namespace tonus::sim
