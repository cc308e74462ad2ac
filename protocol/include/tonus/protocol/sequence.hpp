// Receiver-side bookkeeping for the wrapping counters of the stream:
// the 16-bit sequence number and the 32-bit microsecond device timestamp.
#pragma once

#include <cstdint>

namespace tonus::proto {

// Counts loss, duplication and reordering from 16-bit sequence numbers that
// wrap. Keeps a 64-message history so that a late message is recognised as
// reordered (and taken back out of `lost`) or as a duplicate.
//
// A sender restart is seen three ways: a change of the stream's boot epoch
// (any change; 0 = the sender does not say, the version-1.0 behaviour), a
// jump of more than kResyncThreshold, or a backward step as the first report
// after note_reconnect(). Each counts one resync and loses nothing.
class SequenceTracker {
 public:
  enum class Verdict : std::uint8_t {
    first,      // first message seen (or after a resync)
    in_order,   // exactly the next number
    gap,        // newer than expected: the numbers between are counted lost
    duplicate,  // already seen
    late,       // older than the newest but not seen before: reordered
    stale,      // older than the history window: dropped, counted in `stale`
    resync,     // a sender restart (new boot epoch, or a jump too large to be loss): counting restarts
  };

  // Jumps beyond this are treated as a sender restart rather than loss.
  static constexpr std::uint16_t kResyncThreshold = 4096;
  static constexpr unsigned kWindow = 64;

  // boot_epoch: the stream's byte 3 (0 = unknown).
  Verdict push(std::uint16_t seq, std::uint8_t boot_epoch = 0);
  // The link was reopened: the sender may have rebooted with the same (or no)
  // epoch, so the next report restarts counting if it is not ahead.
  void note_reconnect() { reconnected_ = true; }
  // The sender restarted, known by other means (a CAN heartbeat whose uptime went back).
  void note_restart();

  [[nodiscard]] std::uint64_t received() const { return received_; }
  [[nodiscard]] std::uint64_t lost() const { return lost_; }
  [[nodiscard]] std::uint64_t duplicates() const { return duplicates_; }
  [[nodiscard]] std::uint64_t reordered() const { return reordered_; }
  [[nodiscard]] std::uint64_t stale() const { return stale_; }
  [[nodiscard]] std::uint64_t resyncs() const { return resyncs_; }
  [[nodiscard]] std::uint16_t newest() const { return newest_; }

 private:
  Verdict restart(std::uint16_t seq, std::uint8_t boot_epoch);

  bool started_ = false;
  bool reconnected_ = false;
  std::uint8_t epoch_ = 0;
  std::uint16_t newest_ = 0;
  std::uint64_t history_ = 0;  // bit k: newest_ - k was received
  std::uint64_t received_ = 0;
  std::uint64_t lost_ = 0;
  std::uint64_t duplicates_ = 0;
  std::uint64_t reordered_ = 0;
  std::uint64_t stale_ = 0;
  std::uint64_t resyncs_ = 0;
};

// Extends a wrapping 32-bit microsecond timestamp to 64 bits. Steps are taken
// as the shortest signed distance, so small backwards steps (reordering) work
// and the ~71.6 min wrap is invisible. The first sample maps to itself.
class TimestampUnwrapper {
 public:
  std::int64_t push(std::uint32_t t_us);
  [[nodiscard]] std::int64_t latest() const { return latest_; }

 private:
  bool started_ = false;
  std::uint32_t last_raw_ = 0;
  std::int64_t latest_ = 0;
};

}  // namespace tonus::proto
