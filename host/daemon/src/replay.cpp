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
    : core_(core), output_(output), reader_(std::move(reader)), speed_(speed), duration_s_(reader_.duration_s()) {}

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
  for (;;) {
    // One chunk of look-ahead: the output thread may have reported a frame in
    // the chunk after the one holding its tick.
    recording::Chunk current;
    recording::Chunk ahead;
    recording::Reader::Status next = reader_.next(current);
    bool first = true;
    Step step = Step::next;
    while (next == recording::Reader::Status::chunk) {
      const recording::Reader::Status after = reader_.next(ahead);
      if (first) {
        vmc_pending_ = current.vmc_ticks;
        first_us_ = current.ticks.empty() ? 0 : current.ticks.front().now_us;
        wall_start_us_ = host::steady_now_us();
        paused_us_ = 0;
        first = false;
      }
      if (after == recording::Reader::Status::chunk) {
        vmc_pending_.insert(vmc_pending_.end(), ahead.vmc_ticks.begin(), ahead.vmc_ticks.end());
      }
      std::sort(vmc_pending_.begin(), vmc_pending_.end());
      step = replay_chunk(current);
      if (step != Step::next) break;
      if (after != recording::Reader::Status::chunk) {
        next = after;
        break;
      }
      std::swap(current, ahead);
    }
    if (step == Step::stop) return;
    // At the end with --hold: paused there until a page seeks back, or plays
    // (from the start, as a media player does), or tonusd stops.
    if (step == Step::next && next == recording::Reader::Status::end && hold_at_end_.load()) {
      paused_.store(true);
      while (!stop_.load() && seek_to_s_.load() < 0.0 && paused_.load()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      if (stop_.load()) {
        finish(ReplayEnd::stopped);
        return;
      }
      const double target = seek_to_s_.exchange(-1.0);
      fast_until_s_ = target > 0.0 ? target : -1.0;  // play: from the start, paced
      step = Step::restart;
    }
    if (step == Step::restart) {
      std::string error;
      if (!core_.restart(error) || !reader_.rewind()) {
        finish(ReplayEnd::corrupt, "seeking back: " + (error.empty() ? "the file cannot be rewound" : error));
        return;
      }
      const std::lock_guard<std::mutex> lock(mutex_);
      status_.chunks = 0;
      status_.ticks = 0;
      continue;
    }
    switch (next) {
      case recording::Reader::Status::end: finish(ReplayEnd::finished); break;
      case recording::Reader::Status::truncated: finish(ReplayEnd::truncated); break;
      default: finish(ReplayEnd::corrupt, reader_.error()); break;
    }
    return;
  }
}

void ReplayDriver::pace(std::int64_t now_us) {
  while (paused_.load() && !stop_.load() && seek_to_s_.load() < 0.0 && fast_until_s_ < 0.0) {
    const std::int64_t t0 = host::steady_now_us();
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    paused_us_ += host::steady_now_us() - t0;
  }
  if (speed_ <= 0.0 || fast_until_s_ >= 0.0) return;
  const auto due_us =
      wall_start_us_ + paused_us_ + static_cast<std::int64_t>(static_cast<double>(now_us - first_us_) / speed_);
  const std::int64_t wait_us = due_us - host::steady_now_us();
  if (wait_us > 0) std::this_thread::sleep_for(std::chrono::microseconds(wait_us));
}

ReplayDriver::Step ReplayDriver::replay_chunk(const recording::Chunk& chunk) {
  std::size_t sent = 0;
  for (const recording::TickInputs& t : chunk.ticks) {
    pace(t.now_us);
    if (stop_.load()) {
      finish(ReplayEnd::stopped);
      return Step::stop;
    }
    const double position_s = static_cast<double>(t.now_us - first_us_) * 1e-6;
    if (const double target = seek_to_s_.exchange(-1.0); target >= 0.0) {
      fast_until_s_ = target;
      if (target < position_s) return Step::restart;
    }
    for (const BandSample& b : t.band) core_.push_band(b);
    for (const PoseSample& p : t.poses) core_.push_pose(p);
    for (const Command& c : t.commands) core_.push_command(c);
    core_.tick(t.now_us);
    const std::uint64_t tick = core_.stats().ticks;
    TripleBuffer<Snapshot>& snaps = core_.snapshots();
    const bool fresh = snaps.update();
    const bool silent = fast_until_s_ >= 0.0;  // seeking: no VMC on the way
    auto it = vmc_pending_.begin();
    while (it != vmc_pending_.end() && *it <= tick) {
      if (*it == tick && fresh && output_ != nullptr && !silent) {
        output_->send(snaps.read_slot());
        ++sent;
      }
      ++it;
    }
    vmc_pending_.erase(vmc_pending_.begin(), it);
    if (silent && position_s >= fast_until_s_) {
      // Arrived: pace from here.
      fast_until_s_ = -1.0;
      wall_start_us_ = host::steady_now_us() - static_cast<std::int64_t>(position_s * 1e6 / std::max(speed_, 1e-9));
      paused_us_ = 0;
    }
    const std::lock_guard<std::mutex> lock(mutex_);
    status_.ticks = tick;
    status_.position_s = position_s;
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
    return Step::stop;
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  ++status_.chunks;
  return Step::next;
}

}  // namespace tonus::daemon
