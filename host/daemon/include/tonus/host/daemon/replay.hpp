// tonusd --replay: a recording fed back into a fresh physics core, tick by
// tick, with the inputs each tick consumed when it was recorded; the VMC
// frames go out from the same ticks they were sent from. Same binary, same
// inputs, same outputs: after every chunk the core's output hash is checked
// against the one recorded, and a difference stops the replay (diverged).
//
// Paced at `speed` times the recorded rate (0: as fast as it goes), on a
// thread of its own; pause() and resume() hold it between ticks. seek()
// runs to a position without pacing or VMC; backwards, it restarts the core
// and the file and runs from the start (about 15x real time on this machine).
#pragma once

#include <algorithm>
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
  void seek(double position_s) { seek_to_s_.store(std::max(0.0, position_s)); }
  // At the end, pause there (a page can seek back, or play again from the
  // start) instead of finishing.
  void hold_at_end(bool hold) { hold_at_end_.store(hold); }
  [[nodiscard]] double duration_s() const { return duration_s_; }
  [[nodiscard]] bool done() const { return done_.load(); }
  [[nodiscard]] ReplayStatus status() const;

 private:
  enum class Step : std::uint8_t { next, stop, restart };
  void run();
  Step replay_chunk(const recording::Chunk& chunk);
  void pace(std::int64_t now_us);
  void finish(ReplayEnd end, std::string error = {});

  PhysicsCore& core_;
  VmcOutput* output_;
  recording::Reader reader_;
  double speed_;
  std::thread thread_;
  std::atomic<bool> stop_{false}, paused_{false}, done_{false}, hold_at_end_{false};
  std::atomic<double> seek_to_s_{-1.0};  // a pending seek (negative: none)
  double fast_until_s_ = -1.0;           // running unpaced and silent up to here (a seek)
  double duration_s_ = 0.0;
  mutable std::mutex mutex_;
  ReplayStatus status_;
  std::int64_t first_us_ = 0;
  std::int64_t wall_start_us_ = 0;
  std::int64_t paused_us_ = 0;              // time spent paused, shifted out of the pacing
  std::vector<std::uint64_t> vmc_pending_;  // ticks to send from, sorted
};

}  // namespace tonus::daemon
