// tonusd --record: every input the physics core consumes, stamped with the
// tick that consumed it, and the tick each VMC frame was sent from, written
// to a recording (recording_format.hpp) by a thread of its own.
//
// The physics thread and the output thread only copy into preallocated
// single-producer queues (no allocation, no lock, no I/O). The writer thread
// drains them, closes a chunk every second, writes it whole and flushes it
// (fdatasync), so a killed daemon loses at most the last second. When a queue
// overflows (the disk cannot keep up for several seconds) or a write fails,
// recording stops there, loudly (status().error); the file stays a valid
// recording up to its last chunk, and the daemon goes on.
#pragma once

#include <readerwriterqueue/readerwriterqueue.h>
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "tonus/host/daemon/messages.hpp"
#include "tonus/host/daemon/recording_format.hpp"

namespace tonus::daemon {

struct RecorderStatus {
  std::uint64_t ticks = 0;   // ticks written
  std::uint64_t chunks = 0;  // chunks written
  std::uint64_t bytes = 0;   // file size
  std::uint64_t vmc_frames = 0;
  bool failed = false;
  std::string error;  // why recording stopped early
};

class Recorder {
 public:
  // Creates (truncates) `path` and writes the header; nullptr and `error` when it cannot.
  static std::unique_ptr<Recorder> create(const std::string& path, const recording::Header& header, std::string& error);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  void start();  // the writer thread
  void stop();   // writes what is queued as the last chunk, closes the file

  // Physics thread (one producer): the items a tick consumed, then the tick.
  [[nodiscard]] bool active() const { return !failed_.load(std::memory_order_relaxed); }
  void band(const BandSample& s) { push(band_, s); }
  void pose(const PoseSample& s) { push(poses_, s); }
  void command(const Command& c) { push(commands_, c); }
  void tick(std::int64_t now_us, std::uint64_t tick, std::uint64_t pose_hash, std::uint32_t bands, std::uint32_t poses,
            std::uint32_t commands);
  // Output thread (one producer): a VMC frame went out built from snapshot `tick`.
  void vmc_frame(std::uint64_t tick) { push(vmc_, tick); }

  [[nodiscard]] RecorderStatus status() const;

  // Queue capacities: several seconds of a 1 kHz core with a 120 Hz tracker.
  static constexpr std::size_t kTickQueue = 8192;
  static constexpr std::size_t kBandQueue = 8192;
  static constexpr std::size_t kPoseQueue = 1024;
  static constexpr std::size_t kCommandQueue = 256;
  static constexpr std::size_t kVmcQueue = 2048;

 private:
  struct TickRecord {
    std::int64_t now_us = 0;
    std::uint64_t tick = 0;
    std::uint64_t pose_hash = 0;
    std::uint32_t bands = 0, poses = 0, commands = 0;
  };

  Recorder(int fd, const recording::Header& header);
  template <class Q, class T>
  void push(Q& q, const T& item) {
    if (failed_.load(std::memory_order_relaxed)) return;
    if (!q.try_enqueue(item)) failed_.store(true, std::memory_order_relaxed);
  }
  void run();
  bool drain(recording::Chunk& chunk, bool final);  // false: stop writing
  bool write_chunk(recording::Chunk& chunk);
  void fail(std::string why);

  int fd_ = -1;
  recording::Header header_;
  moodycamel::ReaderWriterQueue<TickRecord> ticks_{kTickQueue};
  moodycamel::ReaderWriterQueue<BandSample> band_{kBandQueue};
  moodycamel::ReaderWriterQueue<PoseSample> poses_{kPoseQueue};
  moodycamel::ReaderWriterQueue<Command> commands_{kCommandQueue};
  moodycamel::ReaderWriterQueue<std::uint64_t> vmc_{kVmcQueue};
  std::atomic<bool> failed_{false};
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::mutex wake_mutex_;
  std::condition_variable wake_;
  mutable std::mutex status_mutex_;
  RecorderStatus status_;
};

}  // namespace tonus::daemon
