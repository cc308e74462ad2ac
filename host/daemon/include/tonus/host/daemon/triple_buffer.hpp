// A triple buffer: one writer publishes whole values, one reader takes the
// newest, neither ever waits for the other (the physics thread hands its
// snapshot to the output and status threads this way). Three slots: the
// writer's, the reader's, and the one in between that they swap through an
// atomic index; a flag bit says the middle slot holds a value not yet read.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace tonus::daemon {

template <typename T>
class TripleBuffer {
 public:
  // The writer's slot: fill it, then publish().
  T& write_slot() { return slots_[write_]; }
  void publish() {
    const std::uint8_t prev = middle_.exchange(static_cast<std::uint8_t>(write_ | kFresh), std::memory_order_acq_rel);
    write_ = prev & kIndexMask;
  }

  // The reader's side: true when a value newer than the last one read was
  // taken (read_slot() then holds it); false leaves read_slot() as it was.
  bool update() {
    if ((middle_.load(std::memory_order_relaxed) & kFresh) == 0) return false;
    const std::uint8_t prev = middle_.exchange(read_, std::memory_order_acq_rel);
    read_ = prev & kIndexMask;
    return true;
  }
  [[nodiscard]] const T& read_slot() const { return slots_[read_]; }

 private:
  static constexpr std::uint8_t kFresh = 0x4;
  static constexpr std::uint8_t kIndexMask = 0x3;
  std::array<T, 3> slots_{};
  std::uint8_t write_ = 0;  // writer-owned
  std::uint8_t read_ = 1;   // reader-owned
  std::atomic<std::uint8_t> middle_{2};
};

}  // namespace tonus::daemon
