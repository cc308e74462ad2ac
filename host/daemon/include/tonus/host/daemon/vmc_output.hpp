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
#include <vector>

#include "tonus/host/daemon/config.hpp"
#include "tonus/host/daemon/histogram.hpp"
#include "tonus/host/daemon/physics_core.hpp"
#include "tonus/host/vmc/pose_out.hpp"

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
  std::uint64_t wire_hash = 0;  // FNV-1a over every datagram sent (vmc::SenderCounters)
  std::string last_error;
};

class Recorder;

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

  // Replay: the sender without the paced thread; the caller sends each
  // snapshot it wants on the wire (the ones the recording says were sent).
  bool open_driven(std::string& error);
  void send(const Snapshot& s);

  // Each frame sent is reported with its snapshot's tick (set before start).
  void set_recorder(Recorder* recorder) { recorder_ = recorder; }

  [[nodiscard]] OutputStatus status() const;
  // Band report arrival -> the send that carried it, us. Read after stop().
  [[nodiscard]] const Histogram& report_to_wire() const { return report_to_wire_; }

 private:
  void run(int realtime_priority);
  bool open_sender(std::string& error);

  OutputConfig config_;
  const sim::Model& model_;
  PhysicsCore& core_;
  std::unique_ptr<vmc::VmcSender> sender_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  mutable std::mutex mutex_;
  OutputStatus status_;
  Histogram report_to_wire_{10.0, 20000};  // 10 us bins up to 200 ms
  Recorder* recorder_ = nullptr;
  bool driven_ = false;
  std::int64_t last_report_us_ = 0;
  vmc::VmcPose pose_;
  std::vector<vmc::VmcObject> objects_;
};

}  // namespace tonus::daemon
