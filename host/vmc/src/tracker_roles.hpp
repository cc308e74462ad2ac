// Which VMC tracker serial is which tracked point. An explicit map (config)
// first; otherwise, once the head has been seen, a heuristic (docs/vmc.md):
//   /VMC/Ext/Hmd/Pos: the first serial is the head.
//   /VMC/Ext/Con/Pos: the hand on the side of the head's vertical plane the
//     controller is on when first seen (left of the facing: left hand); the
//     other hand when that one is taken.
//   /VMC/Ext/Tra/Pos: above 35 % of the head's height (the pelvis sits near
//     55 %, the feet under 10 %): the waist; below, or when the waist is
//     taken, the foot on its side, then the other foot.
// Roles the map names are never given by the heuristic. An assignment is
// kept for the receiver's life (or until reset()); a serial with no free role
// stays unassigned.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tonus/host/reference/trackers.hpp"

namespace tonus::vmc::detail {

enum class TrackerSource : std::uint8_t { hmd, controller, tracker };

class TrackerRoles {
 public:
  explicit TrackerRoles(std::vector<std::pair<std::string, reference::Tracker>> serial_map = {});

  // The role of `serial`, assigning one if the heuristic can; `pose` is the
  // message's (internal frame), `head` the head's latest (nullptr: unseen).
  std::optional<reference::Tracker> role(std::string_view serial, TrackerSource source,
                                         const reference::TrackerPose& pose, const reference::TrackerPose* head);

  void reset() { assigned_.clear(); }
  [[nodiscard]] const std::vector<std::pair<std::string, reference::Tracker>>& assigned() const { return assigned_; }

  static constexpr double kWaistHeightShare = 0.35;

 private:
  [[nodiscard]] bool taken(reference::Tracker t) const;
  std::optional<reference::Tracker> pick(reference::Tracker first, reference::Tracker second) const;

  std::vector<std::pair<std::string, reference::Tracker>> map_;
  std::vector<std::pair<std::string, reference::Tracker>> assigned_;  // by the heuristic
};

}  // namespace tonus::vmc::detail
