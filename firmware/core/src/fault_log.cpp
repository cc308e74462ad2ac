#include "tonus/firmware/fault_log.hpp"

namespace tonus::fw {

void FaultLog::record(proto::FaultCode code, std::uint16_t arg, std::uint32_t time_ms) {
  if (count_ != 0) {
    proto::LogEntry& newest = ring_[(head_ + count_ - 1) % kFaultLogCapacity];
    if (newest.code == code) {
      if (newest.repeats != 0xFF) ++newest.repeats;
      newest.arg = arg;
      return;
    }
  }
  if (count_ == kFaultLogCapacity) {
    head_ = (head_ + 1) % kFaultLogCapacity;  // the oldest goes
    --count_;
    if (dropped_ != 0xFFFF) ++dropped_;
  }
  ring_[(head_ + count_) % kFaultLogCapacity] = proto::LogEntry{time_ms, code, 0, arg};
  ++count_;
}

void FaultLog::take(proto::FaultLog& out) {
  out = proto::FaultLog{};
  const std::size_t n = count_ < proto::FaultLog::kMaxEntries ? count_ : proto::FaultLog::kMaxEntries;
  for (std::size_t k = 0; k < n; ++k) out.entries[k] = ring_[(head_ + k) % kFaultLogCapacity];
  out.count = static_cast<std::uint8_t>(n);
  head_ = (head_ + n) % kFaultLogCapacity;
  count_ -= n;
  out.more = count_ != 0 ? 1 : 0;
  out.dropped = dropped_;
  dropped_ = 0;
}

}  // namespace tonus::fw
