#include "tonus/host/daemon/replay.hpp"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>

#include "tonus/host/transport/host_clock.hpp"

namespace tonus::daemon {

std::string_view to_string(ReplayEnd e) {
  switch (e) {
    case ReplayEnd::running: return "running";
    case ReplayEnd::finished: return "finished";
    case ReplayEnd::truncated: return "truncated";
    case ReplayEnd::corrupt: return "corrupt";
    case ReplayEnd::diverged: return "diverged";
    case ReplayEnd::stopped: return "stopped";
  }
  return "?";
}

ReplayDriver::ReplayDriver(PhysicsCore& core, VmcOutput* output, recording::Reader reader, double speed)
    : core_(core), output_(output), reader_(std::move(reader)), speed_(speed) {}

ReplayDriver::~ReplayDriver() { stop(); }

void ReplayDriver::start() {
  if (thread_.joinable()) return;
  thread_ = std::thread([this] { run(); });
}

void ReplayDriver::stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

ReplayStatus ReplayDriver::status() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return status_;
}

void ReplayDriver::finish(ReplayEnd end, std::string error) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    status_.end = end;
    status_.error = std::move(error);
  }
  done_.store(true);
}

void ReplayDriver::run() {
  // One chunk of look-ahead: the output thread may have reported a frame in
  // the chunk after the one holding its tick.
  recording::Chunk current;
  recording::Chunk ahead;
  recording::Reader::Status next = reader_.next(current);
  bool first = true;
  while (next == recording::Reader::Status::chunk) {
    recording::Reader::Status after = reader_.next(ahead);
    if (first) {
      vmc_pending_ = current.vmc_ticks;
      first_us_ = current.ticks.empty() ? 0 : current.ticks.front().now_us;
      wall_start_us_ = host::steady_now_us();
      first = false;
    }
    if (after == recording::Reader::Status::chunk) {
      vmc_pending_.insert(vmc_pending_.end(), ahead.vmc_ticks.begin(), ahead.vmc_ticks.end());
    }
    std::sort(vmc_pending_.begin(), vmc_pending_.end());
    if (!replay_chunk(current)) return;
    if (after != recording::Reader::Status::chunk) {
      next = after;
      break;
    }
    std::swap(current, ahead);
  }
  switch (next) {
    case recording::Reader::Status::end: finish(ReplayEnd::finished); break;
    case recording::Reader::Status::truncated: finish(ReplayEnd::truncated); break;
    default: finish(ReplayEnd::corrupt, reader_.error()); break;
  }
}

bool ReplayDriver::replay_chunk(const recording::Chunk& chunk) {
  std::size_t sent = 0;
  for (const recording::TickInputs& t : chunk.ticks) {
    while (paused_.load() && !stop_.load()) {
      const std::int64_t t0 = host::steady_now_us();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      paused_us_ += host::steady_now_us() - t0;
    }
    if (stop_.load()) {
      finish(ReplayEnd::stopped);
      return false;
    }
    if (speed_ > 0.0) {
      const auto due_us =
          wall_start_us_ + paused_us_ + static_cast<std::int64_t>(static_cast<double>(t.now_us - first_us_) / speed_);
      const std::int64_t wait_us = due_us - host::steady_now_us();
      if (wait_us > 0) std::this_thread::sleep_for(std::chrono::microseconds(wait_us));
    }
    for (const BandSample& b : t.band) core_.push_band(b);
    for (const PoseSample& p : t.poses) core_.push_pose(p);
    for (const Command& c : t.commands) core_.push_command(c);
    core_.tick(t.now_us);
    const std::uint64_t tick = core_.stats().ticks;
    TripleBuffer<Snapshot>& snaps = core_.snapshots();
    const bool fresh = snaps.update();
    auto it = vmc_pending_.begin();
    while (it != vmc_pending_.end() && *it <= tick) {
      if (*it == tick && fresh && output_ != nullptr) {
        output_->send(snaps.read_slot());
        ++sent;
      }
      ++it;
    }
    vmc_pending_.erase(vmc_pending_.begin(), it);
    const std::lock_guard<std::mutex> lock(mutex_);
    status_.ticks = tick;
    status_.position_s = static_cast<double>(t.now_us - first_us_) * 1e-6;
  }
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    status_.vmc_frames += sent;
  }
  if (core_.stats().output_hash != chunk.pose_hash) {
    finish(ReplayEnd::diverged,
           fmt::format("the outputs differ from the recording's in chunk {} (ticks {} to {}): hash {:016x}, recorded "
                       "{:016x}",
                       status().chunks + 1, chunk.first_tick, core_.stats().ticks, core_.stats().output_hash,
                       chunk.pose_hash));
    return false;
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  ++status_.chunks;
  return true;
}

}  // namespace tonus::daemon
