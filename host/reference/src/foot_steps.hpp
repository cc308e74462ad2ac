// Procedural stepping for 3-point tracking: each foot stays planted until the
// pelvis has carried its ideal place too far away (or turned too far), then
// steps there, one foot at a time, landing at rest where a moving pelvis will
// need it.
#pragma once

#include "tonus/host/reference/tracker_ik.hpp"

namespace tonus::reference::detail {

struct FootTarget {
  sim::Vec3 ankle = sim::Vec3::Zero();  // the ankle joint's world position
  double yaw_rad = 0.0;                 // the foot's heading (flat on the floor)
};

// Advances both feet by dt. `pelvis`/`pelvis_yaw_rad`: the solved pelvis.
// `tracked`: feet a foot tracker places (they never step). Returns true when
// a step started.
bool advance_feet(const IkModel& model, IkState& state, const sim::Vec3& pelvis, double pelvis_yaw_rad, double dt_s,
                  const std::array<bool, 2>& tracked, std::array<FootTarget, 2>& out);

// Puts both feet where a pelvis at rest wants them (the first frame, a reset).
void plant_feet(const IkModel& model, IkState& state, const sim::Vec3& pelvis, double pelvis_yaw_rad);

}  // namespace tonus::reference::detail
