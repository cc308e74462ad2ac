#include "otg_fs_dcd.hpp"

#include "clock.hpp"
#include "registers.hpp"

namespace tonus::f405 {

namespace {

// GINTSTS / GINTMSK
constexpr std::uint32_t kRxFlvl = 1U << 4U, kUsbSusp = 1U << 11U, kUsbRst = 1U << 12U, kEnumDne = 1U << 13U,
                        kIepInt = 1U << 18U, kOepInt = 1U << 19U, kWkupInt = 1U << 31U;
// PCGCCTL: stop the PHY clock / gate HCLK (cleared on resume)
constexpr std::uint32_t kStopPclk = 1U << 0U, kGateHclk = 1U << 1U;
// DIEPCTL / DOEPCTL
constexpr std::uint32_t kUsbAep = 1U << 15U, kStall = 1U << 21U, kCnak = 1U << 26U, kSnak = 1U << 27U,
                        kSd0Pid = 1U << 28U, kEpEna = 1U << 31U;
constexpr std::uint32_t kInterrupt = 3U << 18U;
// DxEPTSIZ
constexpr std::uint32_t kOnePacket = 1U << 19U, kThreeSetups = 3U << 29U;
// DxEPINT
constexpr std::uint32_t kXfrc = 1U << 0U, kStup = 1U << 3U;
// GRXSTSP packet status
constexpr std::uint32_t kOutData = 2, kSetupData = 6;

bool wait_clear(Reg r, std::uint32_t bits) {
  for (std::uint32_t spins = 0; spins < 1000000; ++spins) {
    if ((r.read() & bits) == 0) return true;
  }
  return false;
}

void write_fifo(unsigned ep, const std::uint8_t* data, std::size_t n) {
  for (std::size_t k = 0; k < n; k += 4) {
    std::uint32_t word = 0;
    for (std::size_t b = 0; b < 4 && k + b < n; ++b) word |= static_cast<std::uint32_t>(data[k + b]) << (8U * b);
    otg::fifo(ep).write(word);
  }
}

void read_fifo(std::uint8_t* dst, std::size_t n, std::size_t capacity) {
  for (std::size_t k = 0; k < n; k += 4) {
    const std::uint32_t word = otg::fifo(0).read();
    for (std::size_t b = 0; b < 4 && k + b < n; ++b) {
      if (k + b < capacity) dst[k + b] = static_cast<std::uint8_t>(word >> (8U * b));
    }
  }
}

}  // namespace

bool OtgFsDcd::init() {
  rcc::ahb1enr.set(1U << 0U);  // GPIOA
  rcc::ahb2enr.set(1U << 7U);  // OTGFS
  gpio::configure(gpio::kA, 11, 2, 10);
  gpio::configure(gpio::kA, 12, 2, 10);
  gpio::ospeedr(gpio::kA).set((3U << 22U) | (3U << 24U));

  otg::gahbcfg.write(0);
  otg::gusbcfg.set(1U << 6U);  // PHYSEL: the internal full-speed PHY
  // Core soft reset once the AHB master is idle.
  for (std::uint32_t spins = 0; (otg::grstctl.read() & (1U << 31U)) == 0; ++spins) {
    if (spins > 1000000) return false;
  }
  otg::grstctl.set(1U);
  if (!wait_clear(otg::grstctl, 1U)) return false;

  otg::gccfg.write((1U << 16U) | (1U << 21U));  // PWRDWN off (transceiver on), NOVBUSSENS
  // Force device mode, turnaround 6 (AHB >= 32 MHz), then wait the mandatory 25 ms.
  otg::gusbcfg.write((otg::gusbcfg.read() & ~(0xFU << 10U)) | (6U << 10U) | (1U << 30U) | (1U << 6U));
  const std::uint64_t until = micros() + 25000U;
  while (micros() < until) {
  }
  otg::pcgcctl.write(0);
  otg::dcfg.write(3U);  // full speed (internal PHY), address 0

  otg::grxfsiz.write(128);                         // words
  otg::dieptxf0.write((16U << 16U) | 128U);        // EP0 TX: 16 words at 128
  otg::dieptxf1.write((16U << 16U) | 144U);        // EP1 TX: 16 words at 144
  otg::grstctl.write((1U << 5U) | (0x10U << 6U));  // flush every TX FIFO
  wait_clear(otg::grstctl, 1U << 5U);
  otg::grstctl.write(1U << 4U);  // flush the RX FIFO
  wait_clear(otg::grstctl, 1U << 4U);

  otg::diepmsk.write(kXfrc);
  otg::doepmsk.write(kXfrc | kStup);
  otg::daintmsk.write(0);
  otg::gintsts.write(0xFFFFFFFFU);
  otg::gintmsk.write(kRxFlvl | kUsbSusp | kWkupInt | kUsbRst | kEnumDne | kIepInt | kOepInt);
  otg::gahbcfg.write(1U);  // global interrupt enable
  nvic::priority(kIrqOtgFs, 0x30);
  nvic::enable(kIrqOtgFs);
  otg::dctl.clear(1U << 1U);  // SDIS off: connect the D+ pull-up
  return true;
}

void OtgFsDcd::bus_reset() {
  otg::grstctl.write((1U << 5U) | (0x10U << 6U));
  wait_clear(otg::grstctl, 1U << 5U);
  for (unsigned ep = 0; ep < 4; ++ep) {
    otg::diepint(ep).write(0xFFU);
    otg::doepint(ep).write(0xFFU);
    otg::doepctl(ep).set(kSnak);
  }
  otg::daintmsk.write((1U << 0U) | (1U << 16U));  // EP0 IN and OUT
  otg::dcfg.write(otg::dcfg.read() & ~(0x7FU << 4U));
  ep0_tx_left_ = 0;
  ep0_zlp_ = false;
  ep0_expect_data_ = false;
  ep1_busy_ = false;
  arm_ep0_out();
  if (core_ != nullptr) core_->on_bus_reset();
}

void OtgFsDcd::arm_ep0_out() {
  otg::doeptsiz(0).write(kThreeSetups | kOnePacket | 64U);
  otg::doepctl(0).set(kEpEna | kCnak);
}

void OtgFsDcd::arm_ep1_out() {
  otg::doeptsiz(1).write(kOnePacket | 64U);
  otg::doepctl(1).set(kEpEna | kCnak);
}

void OtgFsDcd::on_irq() {
  const std::uint32_t sts = otg::gintsts.read() & otg::gintmsk.read();
  if ((sts & kUsbRst) != 0) {
    otg::gintsts.write(kUsbRst);
    bus_reset();
  }
  if ((sts & kEnumDne) != 0) {
    otg::gintsts.write(kEnumDne);
    otg::diepctl(0).write(otg::diepctl(0).read() & ~3U);  // EP0 max packet 64
    otg::dctl.set(1U << 8U);                              // CGINAK
  }
  if ((sts & kUsbSusp) != 0) {
    otg::gintsts.write(kUsbSusp);
    if (core_ != nullptr) core_->on_suspend();
  }
  if ((sts & kWkupInt) != 0) {
    // Resume signalling from the host: the configuration is kept (USB 2.0
    // 9.1.1.6), the stream goes on where it was.
    otg::gintsts.write(kWkupInt);
    otg::pcgcctl.clear(kStopPclk | kGateHclk);
    if (core_ != nullptr) core_->on_resume();
  }
  while ((otg::gintsts.read() & kRxFlvl) != 0) receive_packet();
  if ((sts & kOepInt) != 0) out_endpoint_events();
  if ((sts & kIepInt) != 0) in_endpoint_events();
}

void OtgFsDcd::receive_packet() {
  const std::uint32_t st = otg::grxstsp.read();  // pops the status
  const unsigned ep = st & 0xFU;
  const std::size_t count = (st >> 4U) & 0x7FFU;
  const std::uint32_t kind = (st >> 17U) & 0xFU;
  if (kind == kSetupData) {
    read_fifo(setup_.data(), count, setup_.size());
  } else if (kind == kOutData && ep == 0) {
    read_fifo(ep0_rx_.data(), count, ep0_rx_.size());
    ep0_rx_len_ = count < ep0_rx_.size() ? count : ep0_rx_.size();
  } else if (kind == kOutData && ep == usb::kHidEndpoint) {
    read_fifo(ep1_rx_.data(), count, ep1_rx_.size());
    ep1_rx_len_ = count < ep1_rx_.size() ? count : ep1_rx_.size();
  } else if (kind == kOutData) {
    read_fifo(nullptr, count, 0);  // nothing else is open: pop and drop
  }
}

void OtgFsDcd::out_endpoint_events() {
  const std::uint32_t daint = otg::daint.read() >> 16U;
  if ((daint & 1U) != 0) {
    const std::uint32_t events = otg::doepint(0).read();
    otg::doepint(0).write(events);
    if ((events & kStup) != 0) {
      ep0_expect_data_ = false;
      if (core_ != nullptr) core_->on_setup(setup_);
    } else if ((events & kXfrc) != 0 && ep0_expect_data_) {
      ep0_expect_data_ = false;
      if (core_ != nullptr) core_->on_ep0_data(std::span<const std::uint8_t>(ep0_rx_).first(ep0_rx_len_));
    }
    arm_ep0_out();
  }
  if ((daint & (1U << usb::kHidEndpoint)) != 0) {
    const std::uint32_t events = otg::doepint(usb::kHidEndpoint).read();
    otg::doepint(usb::kHidEndpoint).write(events);
    if ((events & kXfrc) != 0 && core_ != nullptr) {
      core_->on_hid_out(std::span<const std::uint8_t>(ep1_rx_).first(ep1_rx_len_));
    }
    arm_ep1_out();
  }
}

void OtgFsDcd::in_endpoint_events() {
  const std::uint32_t daint = otg::daint.read() & 0xFFFFU;
  if ((daint & 1U) != 0) {
    const std::uint32_t events = otg::diepint(0).read();
    otg::diepint(0).write(events);
    if ((events & kXfrc) != 0 && (ep0_tx_left_ != 0 || ep0_zlp_)) ep0_in_next();
  }
  if ((daint & (1U << usb::kHidEndpoint)) != 0) {
    const std::uint32_t events = otg::diepint(usb::kHidEndpoint).read();
    otg::diepint(usb::kHidEndpoint).write(events);
    if ((events & kXfrc) != 0) ep1_busy_ = false;
  }
}

void OtgFsDcd::set_address(std::uint8_t address) {
  // The DWC2 core answers the status stage at address 0 and switches after it.
  otg::dcfg.write((otg::dcfg.read() & ~(0x7FU << 4U)) | (static_cast<std::uint32_t>(address) << 4U));
}

void OtgFsDcd::ep0_in_next() {
  const std::size_t n = ep0_tx_left_ < usb::kEp0Size ? ep0_tx_left_ : usb::kEp0Size;
  if (n == 0) ep0_zlp_ = false;  // this is the zero-length packet
  otg::dieptsiz(0).write(kOnePacket | static_cast<std::uint32_t>(n));
  otg::diepctl(0).set(kEpEna | kCnak);
  write_fifo(0, ep0_tx_, n);
  ep0_tx_ += n;
  ep0_tx_left_ -= n;
}

void OtgFsDcd::ep0_send(std::span<const std::uint8_t> data, bool needs_zlp) {
  ep0_tx_ = data.data();
  ep0_tx_left_ = data.size();
  ep0_zlp_ = needs_zlp || data.empty();
  ep0_in_next();
  arm_ep0_out();  // the host's zero-length OUT status stage
}

void OtgFsDcd::ep0_receive(std::size_t length) {
  ep0_expect_data_ = true;
  ep0_rx_len_ = 0;
  otg::doeptsiz(0).write(kOnePacket | static_cast<std::uint32_t>(length < 64 ? length : 64U));
  otg::doepctl(0).set(kEpEna | kCnak);
}

void OtgFsDcd::ep0_status() {
  otg::dieptsiz(0).write(kOnePacket);
  otg::diepctl(0).set(kEpEna | kCnak);
}

void OtgFsDcd::ep0_stall() {
  otg::diepctl(0).set(kStall);
  otg::doepctl(0).set(kStall);
  arm_ep0_out();  // the stall clears on the next SETUP
}

void OtgFsDcd::configure_hid_endpoints(bool open) {
  if (!open) {
    otg::diepctl(usb::kHidEndpoint).clear(kUsbAep);
    otg::doepctl(usb::kHidEndpoint).clear(kUsbAep);
    otg::daintmsk.clear((1U << usb::kHidEndpoint) | (1U << (16U + usb::kHidEndpoint)));
    ep1_busy_ = false;
    return;
  }
  otg::diepctl(usb::kHidEndpoint).write(64U | kInterrupt | (1U << 22U) | kSd0Pid | kUsbAep);  // TX FIFO 1
  otg::doepctl(usb::kHidEndpoint).write(64U | kInterrupt | kSd0Pid | kUsbAep);
  otg::daintmsk.set((1U << usb::kHidEndpoint) | (1U << (16U + usb::kHidEndpoint)));
  ep1_busy_ = false;
  arm_ep1_out();
}

bool OtgFsDcd::hid_busy() const { return ep1_busy_; }

void OtgFsDcd::hid_halt(bool in, bool halt) {
  const Reg ctl = in ? otg::diepctl(usb::kHidEndpoint) : otg::doepctl(usb::kHidEndpoint);
  if (halt) {
    ctl.set(kStall);
    if (in) {  // a packet still in the FIFO would go out after the halt: drop it
      otg::grstctl.write((1U << 5U) | (usb::kHidEndpoint << 6U));
      wait_clear(otg::grstctl, 1U << 5U);
      ep1_busy_ = false;
    }
    return;
  }
  // Clear the stall and restart the data toggle at DATA0.
  ctl.write((ctl.read() & ~kStall) | kSd0Pid);
  if (!in) arm_ep1_out();
}

bool OtgFsDcd::hid_send(std::span<const std::uint8_t> packet) {
  if (ep1_busy_ || (otg::diepctl(usb::kHidEndpoint).read() & kUsbAep) == 0) return false;
  ep1_busy_ = true;
  otg::dieptsiz(usb::kHidEndpoint).write(kOnePacket | static_cast<std::uint32_t>(packet.size()));
  otg::diepctl(usb::kHidEndpoint).set(kEpEna | kCnak);
  write_fifo(usb::kHidEndpoint, packet.data(), packet.size());
  return true;
}

}  // namespace tonus::f405
