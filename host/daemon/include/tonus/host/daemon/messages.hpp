// What crosses between tonusd's threads: plain fixed-size values, copied
// through single-producer single-consumer queues (moodycamel's
// ReaderWriterQueue, preallocated) or a triple buffer, so the physics thread
// never allocates, blocks or logs.
#pragma once

#include <array>
#include <cstdint>

#include "tonus/host/avatar/gifts.hpp"
#include "tonus/host/daemon/pose_buffer.hpp"
#include "tonus/host/daemon/stiffness_input.hpp"
#include "tonus/sim/capacity.hpp"
#include "tonus/sim/human_bones.hpp"
#include "tonus/sim/math.hpp"

namespace tonus::daemon {

// Band thread -> physics: one stream report's levels.
struct BandSample {
  std::int64_t arrival_us = 0;       // host steady clock
  std::int64_t sampled_host_us = 0;  // the device's report time mapped to the host clock; 0: not synced yet
  Levels levels{};                   // 0..1 per group
  std::uint16_t sequence = 0;
};

enum class GiftKind : std::uint8_t { ball, cube };
std::string_view to_string(GiftKind k);

// Control / demo -> physics.
struct Command {
  enum class Kind : std::uint8_t { gift, clear_gifts, stiffness_override, stiffness_release };
  Kind kind = Kind::gift;
  std::uint32_t id = 0;  // the requester's number, echoed in the gift's reaction
  GiftKind gift = GiftKind::cube;
  avatar::ThrowBall ball;
  avatar::DropCube cube;
  Levels levels{};
};

// Physics -> logger: what the loop would have logged (it never logs itself).
struct Event {
  enum class Kind : std::uint8_t {
    gift_spawned,   // gift, bone, stiffness
    gift_refused,   // gift, bone, error
    gift_reaction,  // gift, bone, stiffness, peak_deflection_m, final: the window after the gift closed
    gifts_cleared,
    avatar_reset,    // flags: B or A reset (diverged)
    reference_jump,  // A and B resynced to a jump in the reference
    band_stale,      // no report for stale_after: easing to the safe default
    band_live,       // reports again
    tracker_state,   // the tracker stream changed state (pose_state)
    stiffness_override,
    stiffness_release,
  };
  Kind kind = Kind::gift_spawned;
  double time_s = 0.0;  // physics time
  std::uint32_t id = 0;
  GiftKind gift = GiftKind::cube;
  sim::Bone bone = sim::Bone::Hips;
  double stiffness = 0.0;
  double natural_hz = 0.0;  // the bone's group drive frequency at that stiffness (the weak gains: Kp = w^2 I)
  double peak_deflection_m = 0.0;
  avatar::GiftError error = avatar::GiftError::none;
  std::uint32_t flags = 0;
  PoseState pose_state = PoseState::none;
  Levels levels{};
};

// One virtual object as the output sees it.
struct ObjectView {
  std::uint32_t id = 0;  // the request's id
  int slot = 0;          // the physics slot: stable while the object lives
  GiftKind kind = GiftKind::cube;
  double size_m = 0.0;  // ball: radius; cube: edge
  sim::Vec3 pos = sim::Vec3::Zero();
  sim::Quat rot = sim::Quat::Identity();
};

// Physics -> output and status (triple buffer): the newest tick's result.
struct Snapshot {
  std::uint64_t tick = 0;
  double time_s = 0.0;
  std::int64_t tick_host_us = 0;  // the tick's deadline, host steady clock
  Qpos qpos{};                    // simulation B's configuration
  Levels stiffness{};             // applied
  bool band_live = false;
  bool override_active = false;
  PoseState pose_state = PoseState::none;
  std::int64_t band_arrival_us = 0;  // arrival of the newest band report this tick used (0: none yet)
  std::array<ObjectView, sim::kMaxObjects> objects{};
  int nobjects = 0;
};

// A contact as the viewer draws it: where, and the force on the avatar or
// object side (N, world, averaged over the step).
struct ContactView {
  sim::Vec3 pos = sim::Vec3::Zero();
  sim::Vec3 force_n = sim::Vec3::Zero();
  bool avatar_on_ground = false;  // an avatar body against the ground (the ZMP's and the support's contacts)
};
inline constexpr std::size_t kViewerContacts = 48;

// Physics -> viewer (triple buffer, every few ticks): the snapshot plus what
// only the viewer draws.
struct ViewerSnapshot {
  Snapshot base;
  Qpos reference{};                                     // simulation A's configuration: the reference as tracked
  std::array<ContactView, kViewerContacts> contacts{};  // the strongest, when B has more
  int ncontacts = 0;
  int contacts_total = 0;  // B's contacts this step
};

}  // namespace tonus::daemon
