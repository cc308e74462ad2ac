#include "tonus/host/daemon/sender_frames.hpp"

namespace tonus::daemon {

void SenderFrames::add(const reference::BodySample& part, std::int64_t arrival_us,
                       const std::array<bool, sim::kBoneCount>* skeleton, std::vector<SenderFrame>& finished) {
  bool repeats = part.root_present && open_.body.root_present;
  for (std::size_t b = 0; b < sim::kBoneCount && !repeats; ++b) repeats = part.present[b] && open_.body.present[b];
  if (repeats && any_) {
    finished.push_back(open_);
    open_ = SenderFrame{};
    any_ = false;
  }
  for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
    if (!part.present[b]) continue;
    open_.body.present[b] = true;
    open_.body.local[b] = part.local[b];
    any_ = true;
  }
  if (part.root_present) {
    open_.body.root_present = true;
    open_.body.root_position = part.root_position;
    open_.body.root_rotation = part.root_rotation;
    any_ = true;
  }
  open_.arrival_us = arrival_us;
  if (!any_ || skeleton == nullptr || !open_.body.root_present) return;
  for (std::size_t b = 0; b < sim::kBoneCount; ++b) {
    if ((*skeleton)[b] && !open_.body.present[b]) return;
  }
  finished.push_back(open_);  // complete: no need to wait for the next frame
  open_ = SenderFrame{};
  any_ = false;
}

}  // namespace tonus::daemon
