#include "tonus/host/daemon/vmc_output.hpp"

#include <pthread.h>
#include <sched.h>

#include <vector>

#include <fmt/format.h>

#include "tonus/host/daemon/recorder.hpp"
#include "tonus/host/transport/host_clock.hpp"
#include "tonus/host/vmc/pose_out.hpp"
#include "tonus/host/vmc/sender.hpp"

namespace tonus::daemon {

VmcOutput::VmcOutput(const OutputConfig& config, const sim::Model& model, PhysicsCore& core)
    : config_(config), model_(model), core_(core) {}

VmcOutput::~VmcOutput() { stop(); }

bool VmcOutput::open_sender(std::string& error) {
  vmc::SenderOptions o;
  o.host = config_.host;
  o.port = config_.port;
  o.bundle = config_.bundle;
  sender_ = std::make_unique<vmc::VmcSender>(o);
  if (!sender_->ok()) {
    error = fmt::format("output.host = \"{}\", output.port = {}: {}", config_.host, config_.port, sender_->error());
    sender_.reset();
    return false;
  }
  objects_.reserve(sim::kMaxObjects);
  return true;
}

bool VmcOutput::start(std::string& error, int realtime_priority) {
  if (!config_.enabled || thread_.joinable()) return true;
  if (!open_sender(error)) return false;
  stop_.store(false);
  thread_ = std::thread([this, realtime_priority] { run(realtime_priority); });
  return true;
}

bool VmcOutput::open_driven(std::string& error) {
  driven_ = true;  // the snapshots are a recording's: their report times are not this run's
  return !config_.enabled || open_sender(error);
}

void VmcOutput::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

OutputStatus VmcOutput::status() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return status_;
}

void VmcOutput::send(const Snapshot& s) {
  if (!sender_ || !vmc::pose_from_qpos(model_, s.qpos, pose_)) return;
  objects_.clear();
  for (int i = 0; i < s.nobjects; ++i) {
    const ObjectView& v = s.objects[static_cast<std::size_t>(i)];
    const double size = v.kind == GiftKind::ball ? 2.0 * v.size_m : v.size_m;  // VMC side: a ball's diameter
    objects_.push_back(vmc::object_to_vmc(
        v.slot, v.kind == GiftKind::ball ? vmc::ObjectKind::ball : vmc::ObjectKind::cube, size, v.pos, v.rot));
  }
  std::array<float, 4> stiffness{};
  for (std::size_t g = 0; g < stiffness.size(); ++g) stiffness[g] = static_cast<float>(s.stiffness[g]);
  sender_->send(pose_, s.time_s, objects_, &stiffness);
  if (recorder_ != nullptr) recorder_->vmc_frame(s.tick);
  const std::int64_t sent_us = host::steady_now_us();
  if (!driven_ && s.band_arrival_us > last_report_us_) {
    report_to_wire_.add(static_cast<double>(sent_us - s.band_arrival_us));
    last_report_us_ = s.band_arrival_us;
  }
  const vmc::SenderCounters& c = sender_->counters();
  const std::lock_guard<std::mutex> lock(mutex_);
  status_.frames = c.frames;
  status_.bundles = c.bundles;
  status_.bytes = c.bytes;
  status_.send_errors = c.send_errors;
  status_.rejected = c.rejected;
  status_.wire_hash = c.wire_hash;
  status_.last_error = sender_->last_send_error();
}

void VmcOutput::run(int realtime_priority) {
  if (realtime_priority > 0) {
    sched_param p{};
    p.sched_priority = realtime_priority;
    pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);  // refused without the capability: runs as it is
  }
  const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / config_.rate_hz));
  auto next = std::chrono::steady_clock::now();
  TripleBuffer<Snapshot>& snaps = core_.snapshots();
  bool have = false;
  while (!stop_.load()) {
    std::this_thread::sleep_until(next);
    next += period;
    if (const auto now = std::chrono::steady_clock::now(); next < now) next = now + period;  // never a burst
    have = snaps.update() || have;
    if (have) send(snaps.read_slot());
  }
}

}  // namespace tonus::daemon
