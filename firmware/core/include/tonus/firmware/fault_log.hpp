// The band's fault log: a fixed ring of the last kFaultLogCapacity faults,
// read (and removed) by the host with get_log. A fault that repeats the
// newest unread entry is merged into it (repeats, saturating) so that a
// fault firing every report cannot flush the others out; a full ring drops
// its oldest entry and counts it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "tonus/protocol/payloads.hpp"

namespace tonus::fw {

inline constexpr std::size_t kFaultLogCapacity = 16;

class FaultLog {
 public:
  void record(proto::FaultCode code, std::uint16_t arg, std::uint32_t time_ms);
  // Moves the oldest entries (at most proto::FaultLog::kMaxEntries) into `out`.
  void take(proto::FaultLog& out);
  [[nodiscard]] std::size_t size() const { return count_; }
  [[nodiscard]] std::uint16_t dropped() const { return dropped_; }

 private:
  std::array<proto::LogEntry, kFaultLogCapacity> ring_{};
  std::size_t head_ = 0;  // oldest
  std::size_t count_ = 0;
  std::uint16_t dropped_ = 0;
};

}  // namespace tonus::fw
