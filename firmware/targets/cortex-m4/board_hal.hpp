// The STM32F405 implementations of the HAL (register level).
//   AdcDmaSampler: TIM2 TRGO at the sample rate triggers ADC1 to scan PA0..PA7
//                  (IN0..IN7); DMA2 stream 0 in double-buffer mode writes each
//                  half straight into one of two SampleBlocks.
//   BxCan:         CAN1 on PB8 (RX) / PB9 (TX), 1 Mbit/s, interrupt-driven
//                  transmit and receive rings, hardware filter on the REQUEST
//                  function (any node: the core picks its own), FIFO transmit
//                  priority (keeps the frames of a stream cycle in order).
//   FlashStorage:  flash sector 1 (16 KiB at 0x08004000).
//   SysTickClock, Led (PC13, active low), Iwdg (1 s), NvicReset.
// USB-HID is usb::DeviceCore over the OTG FS driver in otg_fs_dcd.hpp.
#pragma once

#include <array>
#include <cstdint>

#include "tonus/hal/board.hpp"

namespace tonus::f405 {

class AdcDmaSampler final : public hal::EmgSampler {
 public:
  static constexpr std::size_t kBlockFrames = 2;  // 1 ms at 2 kHz
  [[nodiscard]] fw::FrontEnd front_end() const override;
  bool start(std::uint16_t rate_hz) override;
  const hal::SampleBlock* acquire() override;
  void release() override;
  void on_dma_irq();  // from DMA2_Stream0_IRQHandler

 private:
  std::array<hal::SampleBlock, 2> blocks_{};
  std::array<volatile bool, 2> ready_{};
  volatile std::uint32_t sequence_ = 0;
  std::size_t read_ = 0;
  std::uint16_t rate_hz_ = 0;
};

// Exact bxCAN bit timing (BTR without mode bits) for `bitrate` from the APB1
// clock `pclk_hz`; false if no split of 8..25 quanta divides it exactly.
bool can_bit_timing(std::uint32_t pclk_hz, std::uint32_t bitrate, std::uint32_t& btr);

enum class CanFault : std::uint8_t {
  none,
  no_crystal,  // on the internal oscillator: too inexact for CAN, stays off the bus
  no_timing,   // no exact bit timing from this clock
  no_bus,      // init mode never left (no bus or transceiver): retried every second
};

class BxCan final : public hal::CanPort {
 public:
  static constexpr std::uint32_t kBitrate = 1000000;
  static constexpr std::uint64_t kRetryUs = 1000000;
  // Initialises CAN1 with the bit timing of the clock actually running. False
  // with fault() set if it cannot join the bus; no_bus is retried from send()
  // and receive() every kRetryUs.
  bool init(std::uint8_t node);
  bool send(const proto::CanFrame& frame) override;
  bool receive(proto::CanFrame& frame) override;
  void on_tx_irq();
  void on_rx_irq();
  // Every queued frame has left the mailboxes.
  [[nodiscard]] bool idle() const override;
  [[nodiscard]] CanFault fault() const { return fault_; }
  [[nodiscard]] bool up() const { return up_; }
  [[nodiscard]] std::uint32_t init_retries() const { return init_retries_; }

 private:
  void fill_mailboxes();
  bool retry_later();
  bool ensure_up();
  static constexpr std::size_t kTxRing = 64, kRxRing = 32;
  std::array<proto::CanFrame, kTxRing> tx_{};
  std::array<proto::CanFrame, kRxRing> rx_{};
  volatile std::size_t tx_head_ = 0, tx_tail_ = 0, rx_head_ = 0, rx_tail_ = 0;
  std::uint8_t node_ = 1;
  bool up_ = false;
  CanFault fault_ = CanFault::no_bus;
  std::uint64_t next_retry_us_ = 0;
  std::uint32_t init_retries_ = 0;
};

// Flash sectors 1 and 2 (16 KiB each at 0x08004000, the linker's NVM region).
class FlashStorage final : public hal::Storage {
 public:
  static constexpr std::size_t kSectorSize = std::size_t{16} * 1024;
  static constexpr std::size_t kFirstSector = 1;
  [[nodiscard]] std::size_t sector_size() const override { return kSectorSize; }
  [[nodiscard]] std::size_t sector_count() const override;
  bool read(std::size_t offset, std::span<std::uint8_t> out) override;
  bool erase(std::size_t sector) override;
  bool program(std::size_t offset, std::span<const std::uint8_t> data) override;
};

class SysTickClock final : public hal::Clock {
 public:
  [[nodiscard]] std::uint64_t now_us() const override;
};

class Led final : public hal::StatusLed {
 public:
  void init();
  void show(hal::LedPattern p) override;

 private:
  hal::LedPattern pattern_ = hal::LedPattern::off;
};

class Iwdg final : public hal::Watchdog {
 public:
  void init();  // reads the reset cause first, then starts the watchdog (cannot be stopped)
  void kick() override;
  [[nodiscard]] bool caused_last_reset() const override { return by_watchdog_; }

 private:
  bool by_watchdog_ = false;
};

class NvicReset final : public hal::SystemControl {
 public:
  // SYSRESETREQ at once: fw::Device calls it only once its links have drained
  // (the reply to `reset` has left) or their deadline has passed.
  void reset() override;
  // A boot counter in RTC backup register 0 (kept across resets), read and
  // bumped once per boot; 1..255, never 0.
  [[nodiscard]] std::uint8_t boot_epoch() const override;
  // From RCC_CSR's reset flags, latched before Iwdg::init clears them.
  void latch_reset_cause();
  [[nodiscard]] proto::ResetCause reset_cause() const override { return cause_; }
  // The ROM's USB DFU bootloader (bootloader.hpp).
  [[nodiscard]] bool has_bootloader() const override { return true; }
  void enter_bootloader() override;

 private:
  mutable std::uint8_t epoch_ = 0;
  proto::ResetCause cause_ = proto::ResetCause::unknown;
};

}  // namespace tonus::f405
