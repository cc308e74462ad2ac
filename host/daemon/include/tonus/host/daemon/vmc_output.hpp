// tonusd's output thread: at output.rate_hz it takes the physics core's
// newest snapshot and sends it to the avatar engine as VMC (host/vmc): the
// humanoid's bones, the gifts on tonus's own OSC addresses, and the applied
// stiffness. It also measures how long a band report takes to reach the
// wire: from its arrival on the host to the first send that reflects it.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "tonus/host/daemon/config.hpp"
#include "tonus/host/daemon/histogram.hpp"
#include "tonus/host/daemon/physics_core.hpp"

namespace tonus::vmc {
class VmcSender;
}

namespace tonus::daemon {

struct OutputStatus {
  std::uint64_t frames = 0;
  std::uint64_t bundles = 0;
  std::uint64_t bytes = 0;
  std::uint64_t send_errors = 0;
  std::uint64_t rejected = 0;
  std::string last_error;
};

class VmcOutput {
 public:
  VmcOutput(const OutputConfig& config, const sim::Model& model, PhysicsCore& core);
  ~VmcOutput();
  VmcOutput(const VmcOutput&) = delete;
  VmcOutput& operator=(const VmcOutput&) = delete;

  // false: the address or port is unusable (nothing started). `realtime_priority` > 0: the thread asks for
  // SCHED_FIFO at it (below the physics thread's), so a busy machine delays the wire less.
  bool start(std::string& error, int realtime_priority = 0);
  void stop();

  [[nodiscard]] OutputStatus status() const;
  // Band report arrival -> the send that carried it, us. Read after stop().
  [[nodiscard]] const Histogram& report_to_wire() const { return report_to_wire_; }

 private:
  void run(int realtime_priority);

  OutputConfig config_;
  const sim::Model& model_;
  PhysicsCore& core_;
  std::unique_ptr<vmc::VmcSender> sender_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  mutable std::mutex mutex_;
  OutputStatus status_;
  Histogram report_to_wire_{10.0, 20000};  // 10 us bins up to 200 ms
};

}  // namespace tonus::daemon
