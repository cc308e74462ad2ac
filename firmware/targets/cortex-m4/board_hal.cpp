#include "board_hal.hpp"

#include "clock.hpp"
#include "registers.hpp"

extern "C" {
extern std::uint8_t __nvm_start[];
extern std::uint8_t __nvm_size[];
}

namespace tonus::f405 {

namespace {

constexpr std::uint32_t kGpioAEn = 1U << 0U, kGpioBEn = 1U << 1U, kGpioCEn = 1U << 2U, kDma2En = 1U << 22U;
constexpr std::uint32_t kTim2En = 1U << 0U, kCan1En = 1U << 25U, kAdc1En = 1U << 8U;

void disable_irq() { asm volatile("cpsid i" ::: "memory"); }
void enable_irq() { asm volatile("cpsie i" ::: "memory"); }

}  // namespace

// ---------------------------------------------------------------- sampler

fw::FrontEnd AdcDmaSampler::front_end() const {
  fw::FrontEnd fe;  // 12-bit ADC behind the analogue front end (gain 1000, 1.65 V bias)
  fe.rail_low = 0;
  fe.rail_high = 4095;
  fe.min_rate_hz = 1000;
  fe.max_rate_hz = 2000;
  fe.rate_step_hz = 1000;
  return fe;
}

bool AdcDmaSampler::start(std::uint16_t rate_hz) {
  if (!front_end().supports_rate(rate_hz)) return false;
  rate_hz_ = rate_hz;
  rcc::ahb1enr.set(kGpioAEn | kDma2En);
  rcc::apb1enr.set(kTim2En);
  rcc::apb2enr.set(kAdc1En);
  for (unsigned pin = 0; pin < 8; ++pin) gpio::configure(gpio::kA, pin, 3);  // analog

  tim2::cr1.write(0);
  dma2::s0cr.write(0);
  while ((dma2::s0cr.read() & 1U) != 0) {
  }
  dma2::lifcr.write(0x3DU);  // clear stream 0 flags
  ready_ = {false, false};
  read_ = 0;

  // ADC1: scan IN0..IN7, 84-cycle sampling (21 MHz ADC clock: 4.6 us per channel).
  adc1::ccr.write(1U << 16U);                  // ADCPRE = /4 from APB2 84 MHz
  adc1::cr1.write(1U << 8U);                   // SCAN
  adc1::smpr2.write(0x924924U & 0x00FFFFFFU);  // 100b for channels 0..7
  adc1::sqr1.write(7U << 20U);                 // 8 conversions
  adc1::sqr3.write(0U | (1U << 5U) | (2U << 10U) | (3U << 15U) | (4U << 20U) | (5U << 25U));
  adc1::sqr2.write(6U | (7U << 5U));
  // Trigger TIM2 TRGO (0110) on the rising edge, DMA with DDS (continuous requests).
  adc1::cr2.write((1U << 28U) | (6U << 24U) | (1U << 9U) | (1U << 8U) | 1U);

  // DMA2 stream 0 channel 0: ADC1 -> two SampleBlocks, double-buffer mode, 16-bit, TC interrupt.
  constexpr std::uint32_t items = kBlockFrames * fw::kChannels;
  dma2::s0par.write(adc1::dr.address);
  dma2::s0m0ar.write(reinterpret_cast<std::uint32_t>(blocks_[0].samples.data()));
  dma2::s0m1ar.write(reinterpret_cast<std::uint32_t>(blocks_[1].samples.data()));
  dma2::s0ndtr.write(items);
  dma2::s0fcr.write(0);  // direct mode
  dma2::s0cr.write((1U << 18U) | (2U << 16U) | (1U << 13U) | (1U << 11U) | (1U << 10U) | (1U << 8U) | (1U << 4U));
  dma2::s0cr.set(1U);
  nvic::priority(kIrqDma2Stream0, 0x20);
  nvic::enable(kIrqDma2Stream0);

  // TIM2: update event at the sample rate drives TRGO.
  const std::uint32_t timer_hz = clocks().apb1_timer_hz;
  tim2::psc.write(0);
  tim2::arr.write(timer_hz / rate_hz - 1U);
  tim2::cr2.write(2U << 4U);  // MMS = update
  tim2::egr.write(1U);
  tim2::cr1.write(1U);
  return true;
}

void AdcDmaSampler::on_dma_irq() {
  if ((dma2::lisr.read() & (1U << 5U)) == 0) return;  // TCIF0
  dma2::lifcr.write(1U << 5U);
  // CT names the buffer the DMA writes now; the other one just completed.
  const std::size_t done = (dma2::s0cr.read() & (1U << 19U)) != 0 ? 0 : 1;
  hal::SampleBlock& b = blocks_[done];
  const std::uint32_t seq = sequence_;
  sequence_ = seq + 1U;
  // If the core still holds this half, it was overwritten under it: its
  // sequence number is lost and the new data takes its place.
  b.sequence = seq;
  b.frames = kBlockFrames;
  b.first_sample_us = micros() - kBlockFrames * 1000000U / rate_hz_;
  ready_[done] = true;
}

const hal::SampleBlock* AdcDmaSampler::acquire() {
  if (ready_[read_]) return &blocks_[read_];
  if (ready_[read_ ^ 1U]) read_ ^= 1U;  // resynchronise after an overrun
  return ready_[read_] ? &blocks_[read_] : nullptr;
}

void AdcDmaSampler::release() {
  ready_[read_] = false;
  read_ ^= 1U;
}

// ---------------------------------------------------------------- bxCAN

bool BxCan::init(std::uint8_t node) {
  rcc::ahb1enr.set(kGpioBEn);
  rcc::apb1enr.set(kCan1En);
  gpio::configure(gpio::kB, 8, 2, 9);             // CAN1_RX
  gpio::configure(gpio::kB, 9, 2, 9);             // CAN1_TX
  can1::mcr.write((1U << 6U) | (1U << 2U) | 1U);  // ABOM, TXFP, INRQ (leaves SLEEP)
  std::uint32_t spins = 100000;
  while ((can1::msr.read() & 1U) == 0 && --spins != 0) {
  }
  if (spins == 0) return false;
  // 1 Mbit/s from 42 MHz: prescaler 3, 1 + 11 + 2 = 14 quanta, sample point 85.7 %.
  can1::btr.write((0U << 24U) | (1U << 20U) | (10U << 16U) | 2U);
  // Filter 0, 32-bit mask mode, FIFO 0: standard id REQUEST | node, data frames only.
  can1::fmr.set(1U);
  can1::fs1r.set(1U);
  can1::fm1r.clear(1U);
  can1::ffa1r.clear(1U);
  // Every node's REQUEST id (0x600..0x61F) passes: the core's reassembler picks
  // its own node, so a node id changed by set_config needs no filter update.
  (void)node;
  can1::f0r1.write(static_cast<std::uint32_t>(proto::can::Function::request) << 21U);
  can1::f0r2.write((0x7E0U << 21U) | (1U << 2U) | (1U << 1U));  // function bits, IDE, RTR must match
  can1::fa1r.set(1U);
  can1::fmr.clear(1U);
  can1::mcr.clear(1U);
  spins = 100000;
  while ((can1::msr.read() & 1U) != 0 && --spins != 0) {
  }
  if (spins == 0) return false;      // no bus: 11 recessive bits never seen
  can1::ier.write((1U << 1U) | 1U);  // FMPIE0, TMEIE
  nvic::priority(kIrqCan1Tx, 0x40);
  nvic::priority(kIrqCan1Rx0, 0x40);
  nvic::enable(kIrqCan1Tx);
  nvic::enable(kIrqCan1Rx0);
  return true;
}

bool BxCan::send(const proto::CanFrame& frame) {
  disable_irq();
  const std::size_t next = (tx_head_ + 1) % kTxRing;
  const bool ok = next != tx_tail_;
  if (ok) {
    tx_[tx_head_] = frame;
    tx_head_ = next;
    fill_mailboxes();
  }
  enable_irq();
  return ok;
}

void BxCan::fill_mailboxes() {
  while (tx_tail_ != tx_head_) {
    const std::uint32_t tsr = can1::tsr.read();
    const std::uint32_t empty = (tsr >> 26U) & 7U;  // TME0..2
    if (empty == 0) return;
    const unsigned mb = (tsr >> 24U) & 3U;  // CODE: next empty mailbox
    const proto::CanFrame& f = tx_[tx_tail_];
    const bool ext = (f.flags & proto::CanFrame::kExtended) != 0;
    const std::uint32_t id = ext ? ((f.id << 3U) | (1U << 2U)) : (f.id << 21U);
    const std::uint32_t rtr = (f.flags & proto::CanFrame::kRemote) != 0 ? (1U << 1U) : 0U;
    can1::tdtr(mb).write(f.dlc);
    can1::tdlr(mb).write(f.data[0] | (f.data[1] << 8U) | (f.data[2] << 16U) |
                         (static_cast<std::uint32_t>(f.data[3]) << 24U));
    can1::tdhr(mb).write(f.data[4] | (f.data[5] << 8U) | (f.data[6] << 16U) |
                         (static_cast<std::uint32_t>(f.data[7]) << 24U));
    can1::tir(mb).write(id | rtr | 1U);  // TXRQ
    tx_tail_ = (tx_tail_ + 1) % kTxRing;
  }
}

void BxCan::on_tx_irq() {
  can1::tsr.write((1U << 0U) | (1U << 8U) | (1U << 16U));  // clear RQCP0..2
  fill_mailboxes();
}

void BxCan::on_rx_irq() {
  while ((can1::rf0r.read() & 3U) != 0) {
    const std::uint32_t rir = can1::rir.read();
    proto::CanFrame f{};
    const bool ext = (rir & (1U << 2U)) != 0;
    f.id = ext ? (rir >> 3U) : (rir >> 21U);
    if (ext) f.flags |= proto::CanFrame::kExtended;
    if ((rir & (1U << 1U)) != 0) f.flags |= proto::CanFrame::kRemote;
    f.dlc = static_cast<std::uint8_t>(can1::rdtr.read() & 0xFU);
    if (f.dlc > 8) f.dlc = 8;
    const std::uint32_t lo = can1::rdlr.read(), hi = can1::rdhr.read();
    for (unsigned k = 0; k < 4; ++k) {
      f.data[k] = static_cast<std::uint8_t>(lo >> (8U * k));
      f.data[4 + k] = static_cast<std::uint8_t>(hi >> (8U * k));
    }
    can1::rf0r.set(1U << 5U);  // RFOM0: release the FIFO slot
    const std::size_t next = (rx_head_ + 1) % kRxRing;
    if (next != rx_tail_) {  // full: the frame is dropped, the host retries its command
      rx_[rx_head_] = f;
      rx_head_ = next;
    }
  }
}

bool BxCan::idle() const { return tx_tail_ == tx_head_ && ((can1::tsr.read() >> 26U) & 7U) == 7U; }

bool BxCan::receive(proto::CanFrame& frame) {
  disable_irq();
  const bool any = rx_tail_ != rx_head_;
  if (any) {
    frame = rx_[rx_tail_];
    rx_tail_ = (rx_tail_ + 1) % kRxRing;
  }
  enable_irq();
  return any;
}

// ---------------------------------------------------------------- flash

std::size_t FlashStorage::size() const { return reinterpret_cast<std::size_t>(__nvm_size); }

bool FlashStorage::read(std::size_t offset, std::span<std::uint8_t> out) {
  if (offset > size() || out.size() > size() - offset) return false;
  const volatile std::uint8_t* src = __nvm_start + offset;
  for (std::uint8_t& b : out) b = *src++;
  return true;
}

namespace {

constexpr std::uint32_t kFlashBusy = 1U << 16U, kFlashErrors = 0xF0U;  // PGSERR PGPERR PGAERR WRPERR

bool flash_wait() {
  while ((flash::sr.read() & kFlashBusy) != 0) {
  }
  const bool ok = (flash::sr.read() & kFlashErrors) == 0;
  flash::sr.write(kFlashErrors);
  return ok;
}

void flash_unlock() {
  if ((flash::cr.read() & (1U << 31U)) != 0) {
    flash::keyr.write(0x45670123U);
    flash::keyr.write(0xCDEF89ABU);
  }
}

}  // namespace

bool FlashStorage::erase() {
  // Sector 1. The CPU stalls on instruction fetch for the erase (~250 ms):
  // sample blocks in that time are counted lost; the watchdog is set long enough.
  flash_unlock();
  flash_wait();
  flash::cr.write((2U << 8U) | (1U << 3U) | (1U << 1U));  // PSIZE x32, SNB 1, SER
  flash::cr.set(1U << 16U);                               // STRT
  const bool ok = flash_wait();
  flash::cr.write(1U << 31U);  // lock
  return ok;
}

bool FlashStorage::program(std::size_t offset, std::span<const std::uint8_t> data) {
  if (offset > size() || data.size() > size() - offset) return false;
  flash_unlock();
  bool ok = flash_wait();
  flash::cr.write(1U);  // PG, PSIZE x8
  volatile std::uint8_t* dst = __nvm_start + offset;
  for (std::size_t k = 0; k < data.size() && ok; ++k) {
    if (data[k] == 0xFF) continue;  // erased already
    dst[k] = data[k];
    ok = flash_wait();
  }
  flash::cr.write(1U << 31U);
  return ok;
}

// ---------------------------------------------------------------- misc

std::uint64_t SysTickClock::now_us() const { return micros(); }

void Led::init() {
  rcc::ahb1enr.set(kGpioCEn);
  gpio::configure(gpio::kC, 13, 1);
  gpio::bsrr(gpio::kC).write(1U << 13U);  // off (active low)
}

void Led::show(hal::LedPattern p) {
  pattern_ = p;
  // Steady on when running and calibrated; blink codes for the rest (2 Hz
  // uncalibrated, 8 Hz calibrating, 1 Hz fault), from the millisecond clock.
  const std::uint64_t ms = micros() / 1000U;
  bool on = false;
  switch (p) {
    case hal::LedPattern::off: on = false; break;
    case hal::LedPattern::booting:
    case hal::LedPattern::running: on = true; break;
    case hal::LedPattern::uncalibrated: on = (ms / 250U) % 2U == 0; break;
    case hal::LedPattern::calibrating: on = (ms / 62U) % 2U == 0; break;
    case hal::LedPattern::fault: on = (ms / 500U) % 2U == 0; break;
  }
  gpio::bsrr(gpio::kC).write(on ? (1U << (13U + 16U)) : (1U << 13U));
}

void Iwdg::init() {
  by_watchdog_ = (rcc::csr.read() & (1U << 29U)) != 0;  // IWDGRSTF
  rcc::csr.set(1U << 24U);                              // RMVF: clear the reset flags
  // LSI 32 kHz / 64 = 500 Hz; reload 500 -> 1 s, long enough for a sector erase.
  iwdg::kr.write(0x5555U);
  iwdg::pr.write(4U);
  iwdg::rlr.write(500U);
  iwdg::kr.write(0xCCCCU);
}

void Iwdg::kick() { iwdg::kr.write(0xAAAAU); }

void NvicReset::reset() {
  // The response to the reset command is still in the CAN queue: let it go out.
  const std::uint64_t deadline = micros() + 20000U;
  while (can_ != nullptr && !can_->idle() && micros() < deadline) {
  }
  asm volatile("dsb" ::: "memory");
  scb::aircr.write((0x5FAU << 16U) | (1U << 2U));  // VECTKEY, SYSRESETREQ
  asm volatile("dsb" ::: "memory");
  for (;;) {
  }
}

}  // namespace tonus::f405
