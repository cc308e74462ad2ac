// Where the humanoid's feet are, to put the clip's floor at z = 0: the lowest
// point of each foot's collision shapes (foot and toes) in a configuration.
#pragma once

#include <array>
#include <vector>

#include "tonus/host/balance/contacts.hpp"
#include "tonus/sim/model.hpp"

namespace tonus::reference::detail {

struct FloorFit {
  double offset_m = 0.0;    // to add to every root height
  std::size_t samples = 0;  // foot contacts it was measured on (0: the lowest frames instead)
};

// The height shift that puts the median lowest point of the feet in contact
// (per the clip's contact track) at z = 0; without contacts, the 5th
// percentile of each frame's lowest foot point.
FloorFit fit_floor(const sim::Model& model, const std::vector<std::array<double, sim::kMaxQpos>>& qpos,
                   const balance::ContactTrack& contacts);

}  // namespace tonus::reference::detail
