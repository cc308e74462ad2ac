#include "tracker_roles.hpp"

namespace tonus::vmc::detail {

using reference::Tracker;

namespace {

// The head's left, horizontal and unit: its +Y (the internal frame's left;
// an HMD looks along its own +X once converted from Unity's +Z). World +Y
// when the head looks straight up or down.
sim::Vec3 head_left(const reference::TrackerPose& head) {
  sim::Vec3 left = head.rot * sim::Vec3::UnitY();
  left.z() = 0.0;
  const double n = left.norm();
  return n > 0.1 ? sim::Vec3(left / n) : sim::Vec3(sim::Vec3::UnitY());
}

bool on_left(const reference::TrackerPose& pose, const reference::TrackerPose& head) {
  return (pose.pos_m - head.pos_m).dot(head_left(head)) >= 0.0;
}

}  // namespace

TrackerRoles::TrackerRoles(std::vector<std::pair<std::string, Tracker>> serial_map) : map_(std::move(serial_map)) {}

bool TrackerRoles::taken(Tracker t) const {
  for (const auto& [serial, role] : map_) {
    if (role == t) return true;
  }
  for (const auto& [serial, role] : assigned_) {
    if (role == t) return true;
  }
  return false;
}

std::optional<Tracker> TrackerRoles::pick(Tracker first, Tracker second) const {
  if (!taken(first)) return first;
  if (!taken(second)) return second;
  return std::nullopt;
}

std::optional<Tracker> TrackerRoles::role(std::string_view serial, TrackerSource source,
                                          const reference::TrackerPose& pose, const reference::TrackerPose* head) {
  for (const auto& [s, r] : map_) {
    if (s == serial) return r;
  }
  for (const auto& [s, r] : assigned_) {
    if (s == serial) return r;
  }
  std::optional<Tracker> r;
  if (source == TrackerSource::hmd) {
    if (!taken(Tracker::head)) r = Tracker::head;
  } else if (head != nullptr && head->valid) {
    const bool left = on_left(pose, *head);
    if (source == TrackerSource::controller) {
      r = left ? pick(Tracker::left_hand, Tracker::right_hand) : pick(Tracker::right_hand, Tracker::left_hand);
    } else {
      const bool high = head->pos_m.z() > 0.0 && pose.pos_m.z() > kWaistHeightShare * head->pos_m.z();
      if (high && !taken(Tracker::waist)) {
        r = Tracker::waist;
      } else {
        r = left ? pick(Tracker::left_foot, Tracker::right_foot) : pick(Tracker::right_foot, Tracker::left_foot);
      }
    }
  }
  if (r) assigned_.emplace_back(std::string(serial), *r);
  return r;
}

}  // namespace tonus::vmc::detail
