// tonusd's tracker thread: turns the configured tracker source into
// reference poses (the humanoid's qpos) stamped with host time, and hands them
// to the physics core's jitter buffer.
//   bvh: a clip retargeted onto the humanoid once at start, then played at its
//        own frame rate (looping: the clip restarts, the avatar resyncs);
//   vmc: the VMC protocol over OSC/UDP (host/vmc): performer mode (bone
//        rotations, retargeted) or tracker mode (3 or 6 points, solved by IK).
// Retargeting and IK run here, not on the physics thread.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "tonus/host/daemon/config.hpp"
#include "tonus/host/daemon/physics_core.hpp"
#include "tonus/host/reference/body_retarget.hpp"
#include "tonus/host/reference/clip_reference.hpp"
#include "tonus/host/reference/trackers.hpp"

namespace tonus::daemon {

struct TrackerStatus {
  std::string source;         // what is playing or listened to
  std::uint64_t frames = 0;   // poses handed to the physics core
  std::uint64_t dropped = 0;  // the queue was full
  double rate_hz = 0.0;       // over the last second
  std::uint64_t loops = 0;    // bvh: times the clip restarted
  std::uint64_t vmc_messages = 0, vmc_ignored = 0, vmc_malformed = 0;
  std::string balance;  // a VMC performer's balance stage: how it runs (empty: off or not started)
};

class TrackerInput {
 public:
  TrackerInput(const TrackerConfig& config, const sim::Model& model, PhysicsCore& core);
  ~TrackerInput();
  TrackerInput(const TrackerInput&) = delete;
  TrackerInput& operator=(const TrackerInput&) = delete;

  // Loads the clip or opens the port; false with `error` (nothing started).
  bool start(std::string& error);
  void stop();
  [[nodiscard]] TrackerStatus status() const;
  [[nodiscard]] int vmc_port() const;  // the bound port (tracker.listen_port = 0 picks one); 0: not listening

 private:
  void run_bvh();
  void run_vmc();
  void count_frame(bool pushed);
  bool solve_body(const reference::BodySample& body, Qpos& qpos);
  // tracker.balance = "online" on a performer stream: through BodyBalance,
  // once the sender's frame time is measured; false while the filter fills.
  bool balance_body(const reference::BodySample& body, std::int64_t arrival_us, Qpos& qpos);
  bool solve_trackers(reference::TrackerFrame frame, std::int64_t arrival_us, Qpos& qpos);

  TrackerConfig config_;
  const sim::Model& model_;
  PhysicsCore& core_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  reference::ClipReference clip_;
  mutable std::mutex mutex_;
  TrackerStatus status_;
  std::int64_t rate_window_start_us_ = 0;
  std::uint64_t rate_window_frames_ = 0;
  struct Vmc;
  std::unique_ptr<Vmc> vmc_;
};

// The bundled clip tonusd plays when tracker.bvh_path is empty.
std::string default_bvh_path();

}  // namespace tonus::daemon
