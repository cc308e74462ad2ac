#include "tonus/host/daemon/vmc_output.hpp"

#include <pthread.h>
#include <sched.h>

#include <vector>

#include <fmt/format.h>

#include "tonus/host/transport/host_clock.hpp"
#include "tonus/host/vmc/pose_out.hpp"
#include "tonus/host/vmc/sender.hpp"

namespace tonus::daemon {

VmcOutput::VmcOutput(const OutputConfig& config, const sim::Model& model, PhysicsCore& core)
    : config_(config), model_(model), core_(core) {}

VmcOutput::~VmcOutput() { stop(); }

bool VmcOutput::start(std::string& error, int realtime_priority) {
  if (!config_.enabled || thread_.joinable()) return true;
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
  stop_.store(false);
  thread_ = std::thread([this, realtime_priority] { run(realtime_priority); });
  return true;
}

void VmcOutput::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

OutputStatus VmcOutput::status() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return status_;
}

void VmcOutput::run(int realtime_priority) {
  if (realtime_priority > 0) {
    sched_param p{};
    p.sched_priority = realtime_priority;
    pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);  // refused without the capability: runs as it is
  }
  const auto period = std::chrono::nanoseconds(static_cast<std::int64_t>(1e9 / config_.rate_hz));
  auto next = std::chrono::steady_clock::now();
  vmc::VmcPose pose;
  std::vector<vmc::VmcObject> objects;
  objects.reserve(sim::kMaxObjects);
  std::int64_t last_report_us = 0;
  TripleBuffer<Snapshot>& snaps = core_.snapshots();
  bool have = false;
  while (!stop_.load()) {
    std::this_thread::sleep_until(next);
    next += period;
    if (const auto now = std::chrono::steady_clock::now(); next < now) next = now + period;  // never a burst
    have = snaps.update() || have;
    if (!have) continue;
    const Snapshot& s = snaps.read_slot();
    if (!vmc::pose_from_qpos(model_, s.qpos, pose)) continue;
    objects.clear();
    for (int i = 0; i < s.nobjects; ++i) {
      const ObjectView& v = s.objects[static_cast<std::size_t>(i)];
      const double size = v.kind == GiftKind::ball ? 2.0 * v.size_m : v.size_m;  // VMC side: a ball's diameter
      objects.push_back(vmc::object_to_vmc(
          v.slot, v.kind == GiftKind::ball ? vmc::ObjectKind::ball : vmc::ObjectKind::cube, size, v.pos, v.rot));
    }
    std::array<float, 4> stiffness{};
    for (std::size_t g = 0; g < stiffness.size(); ++g) stiffness[g] = static_cast<float>(s.stiffness[g]);
    sender_->send(pose, s.time_s, objects, &stiffness);
    const std::int64_t sent_us = host::steady_now_us();
    if (s.band_arrival_us > last_report_us) {
      report_to_wire_.add(static_cast<double>(sent_us - s.band_arrival_us));
      last_report_us = s.band_arrival_us;
    }
    const vmc::SenderCounters& c = sender_->counters();
    const std::lock_guard<std::mutex> lock(mutex_);
    status_.frames = c.frames;
    status_.bundles = c.bundles;
    status_.bytes = c.bytes;
    status_.send_errors = c.send_errors;
    status_.rejected = c.rejected;
    status_.last_error = sender_->last_send_error();
  }
}

}  // namespace tonus::daemon
