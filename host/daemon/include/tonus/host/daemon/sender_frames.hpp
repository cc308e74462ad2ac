// A VMC performer's frames as the sender made them, out of the bundles the
// receiver reports one by one: a sender's frame may come in several bundles,
// and one receive() call may hold part of a frame or more than one. A frame
// ends when it has every bone of the sender's skeleton and the root, or when
// a bundle brings a bone (or the root) it already has: the next frame has
// begun. The online balance filter counts time in frames, so a frame split
// over two calls must not count twice, nor two frames once.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "tonus/host/reference/body_retarget.hpp"
#include "tonus/sim/human_bones.hpp"

namespace tonus::daemon {

struct SenderFrame {
  reference::BodySample body;
  std::int64_t arrival_us = 0;  // when its last bundle arrived
};

class SenderFrames {
 public:
  // One bundle's bones and root. `skeleton`: the bones the sender's skeleton
  // has (null while it is not known: frames then end only when one repeats).
  // Frames that end are appended to `finished`, in order.
  void add(const reference::BodySample& part, std::int64_t arrival_us,
           const std::array<bool, sim::kBoneCount>* skeleton, std::vector<SenderFrame>& finished);

 private:
  SenderFrame open_;
  bool any_ = false;
};

}  // namespace tonus::daemon
