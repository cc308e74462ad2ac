// tonusd --replay: a recording fed back into a fresh physics core, tick by
// tick, with the inputs each tick consumed when it was recorded; the VMC
// frames go out from the same ticks they were sent from. Same binary, same
// inputs, same outputs: after every chunk the core's output hash is checked
// against the one recorded, and a difference stops the replay (diverged).
//
// Paced at `speed` times the recorded rate (0: as fast as it goes), on a
// thread of its own; pause() and resume() hold it between ticks.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include "tonus/host/daemon/physics_core.hpp"
#include "tonus/host/daemon/recording_format.hpp"
#include "tonus/host/daemon/vmc_output.hpp"

namespace tonus::daemon {

enum class ReplayEnd : std::uint8_t {
  running,
  finished,   // the whole file, every chunk verified
  truncated,  // the file ends inside a chunk: replayed to the last whole one
  corrupt,    // a chunk failed its checksum or did not decode: replayed up to it
  diverged,   // the outputs differ from the recording's (a different binary or machine)
  stopped,    // asked to stop
};
std::string_view to_string(ReplayEnd e);

struct ReplayStatus {
  ReplayEnd end = ReplayEnd::running;
  std::string error;  // for corrupt and diverged
  std::uint64_t ticks = 0;
  std::uint64_t chunks = 0;  // verified
  std::uint64_t vmc_frames = 0;
  double position_s = 0.0;  // into the recording
};

class ReplayDriver {
 public:
  // `output` may be nullptr (no VMC). The reader is positioned after its header.
  ReplayDriver(PhysicsCore& core, VmcOutput* output, recording::Reader reader, double speed);
  ~ReplayDriver();
  ReplayDriver(const ReplayDriver&) = delete;
  ReplayDriver& operator=(const ReplayDriver&) = delete;

  void start();
  void stop();
  void pause() { paused_.store(true); }
  void resume() { paused_.store(false); }
  [[nodiscard]] bool paused() const { return paused_.load(); }
  [[nodiscard]] bool done() const { return done_.load(); }
  [[nodiscard]] ReplayStatus status() const;

 private:
  void run();
  bool replay_chunk(const recording::Chunk& chunk);  // false: stop
  void finish(ReplayEnd end, std::string error = {});

  PhysicsCore& core_;
  VmcOutput* output_;
  recording::Reader reader_;
  double speed_;
  std::thread thread_;
  std::atomic<bool> stop_{false}, paused_{false}, done_{false};
  mutable std::mutex mutex_;
  ReplayStatus status_;
  std::int64_t first_us_ = 0;
  std::int64_t wall_start_us_ = 0;
  std::int64_t paused_us_ = 0;              // time spent paused, shifted out of the pacing
  std::vector<std::uint64_t> vmc_pending_;  // ticks to send from, sorted
};

}  // namespace tonus::daemon
