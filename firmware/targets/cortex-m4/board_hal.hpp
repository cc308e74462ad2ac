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

class BxCan final : public hal::CanPort {
 public:
  // Initialises CAN1; false if the controller does not leave init mode (no transceiver/bus).
  bool init(std::uint8_t node);
  bool send(const proto::CanFrame& frame) override;
  bool receive(proto::CanFrame& frame) override;
  void on_tx_irq();
  void on_rx_irq();
  // Every queued frame has left the mailboxes.
  [[nodiscard]] bool idle() const;

 private:
  void fill_mailboxes();
  static constexpr std::size_t kTxRing = 64, kRxRing = 32;
  std::array<proto::CanFrame, kTxRing> tx_{};
  std::array<proto::CanFrame, kRxRing> rx_{};
  volatile std::size_t tx_head_ = 0, tx_tail_ = 0, rx_head_ = 0, rx_tail_ = 0;
};

class FlashStorage final : public hal::Storage {
 public:
  [[nodiscard]] std::size_t size() const override;
  bool read(std::size_t offset, std::span<std::uint8_t> out) override;
  bool erase() override;
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
  explicit NvicReset(const BxCan* can) : can_(can) {}
  void reset() override;  // lets the CAN queue drain (<= 20 ms), then SYSRESETREQ

 private:
  const BxCan* can_;
};

}  // namespace tonus::f405
