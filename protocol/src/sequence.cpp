#include "tonus/protocol/sequence.hpp"

namespace tonus::proto {

SequenceTracker::Verdict SequenceTracker::restart(std::uint16_t seq, std::uint8_t boot_epoch) {
  ++resyncs_;
  epoch_ = boot_epoch;
  newest_ = seq;
  history_ = 1;
  ++received_;
  return Verdict::resync;
}

void SequenceTracker::note_restart() {
  if (!started_) return;  // nothing counted yet: the next report is simply the first
  started_ = false;
  ++resyncs_;
}

SequenceTracker::Verdict SequenceTracker::push(std::uint16_t seq, std::uint8_t boot_epoch) {
  const bool reconnected = reconnected_;
  reconnected_ = false;
  if (!started_) {
    started_ = true;
    epoch_ = boot_epoch;
    newest_ = seq;
    history_ = 1;
    ++received_;
    return Verdict::first;
  }
  if (boot_epoch != epoch_) return restart(seq, boot_epoch);
  // Signed distance modulo 2^16: positive means newer.
  const auto ahead = static_cast<std::int16_t>(static_cast<std::uint16_t>(seq - newest_));
  const int distance = ahead;
  if (distance > kResyncThreshold || distance < -kResyncThreshold || (reconnected && distance <= 0)) {
    return restart(seq, boot_epoch);
  }
  if (distance > 0) {
    lost_ += static_cast<std::uint64_t>(distance - 1);
    history_ = static_cast<unsigned>(distance) >= kWindow ? 0 : history_ << static_cast<unsigned>(distance);
    history_ |= 1U;
    newest_ = seq;
    ++received_;
    return distance == 1 ? Verdict::in_order : Verdict::gap;
  }
  if (distance == 0) {
    ++duplicates_;
    return Verdict::duplicate;
  }
  const auto back = static_cast<unsigned>(-distance);
  if (back >= kWindow) {
    ++stale_;
    return Verdict::stale;
  }
  const std::uint64_t bit = std::uint64_t{1} << back;
  if ((history_ & bit) != 0) {
    ++duplicates_;
    return Verdict::duplicate;
  }
  history_ |= bit;
  ++received_;
  ++reordered_;
  if (lost_ > 0) --lost_;  // it was counted lost when the gap opened
  return Verdict::late;
}

std::int64_t TimestampUnwrapper::push(std::uint32_t t_us) {
  if (!started_) {
    started_ = true;
    last_raw_ = t_us;
    latest_ = t_us;
    return latest_;
  }
  const auto step = static_cast<std::int32_t>(t_us - last_raw_);
  last_raw_ = t_us;
  latest_ += step;
  return latest_;
}

}  // namespace tonus::proto
