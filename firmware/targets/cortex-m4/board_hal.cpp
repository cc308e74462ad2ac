#include "board_hal.hpp"

#include "bootloader.hpp"
#include "clock.hpp"
#include "registers.hpp"

#if defined(TONUS_FAKE_REGISTERS)
#include <span>
namespace tonus::f405 {
std::span<std::uint8_t> fake_nvm_area();  // the host test's flash sectors
}
#else
extern "C" {
extern std::uint8_t __nvm_start[];
extern std::uint8_t __nvm_size[];
}
#endif

namespace tonus::f405 {

namespace {

constexpr std::uint32_t kGpioAEn = 1U << 0U, kGpioBEn = 1U << 1U, kGpioCEn = 1U << 2U, kDma2En = 1U << 22U;
constexpr std::uint32_t kTim2En = 1U << 0U, kCan1En = 1U << 25U, kAdc1En = 1U << 8U;

// Four data bytes as a mailbox word (byte 0 lowest).
std::uint32_t le32(const std::uint8_t* b) {
  return static_cast<std::uint32_t>(b[0]) | (static_cast<std::uint32_t>(b[1]) << 8U) |
         (static_cast<std::uint32_t>(b[2]) << 16U) | (static_cast<std::uint32_t>(b[3]) << 24U);
}

// The DMA controller sees 32-bit bus addresses (the host tests' pointers are wider).
std::uint32_t bus_address(const void* p) { return static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(p)); }

volatile std::uint8_t* nvm_base() {
#if defined(TONUS_FAKE_REGISTERS)
  return fake_nvm_area().data();
#else
  return __nvm_start;
#endif
}

std::size_t nvm_bytes() {
#if defined(TONUS_FAKE_REGISTERS)
  return fake_nvm_area().size();
#else
  return reinterpret_cast<std::size_t>(__nvm_size);
#endif
}

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
  dma2::s0m0ar.write(bus_address(blocks_[0].samples.data()));
  dma2::s0m1ar.write(bus_address(blocks_[1].samples.data()));
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

bool can_bit_timing(std::uint32_t pclk_hz, std::uint32_t bitrate, std::uint32_t& btr) {
  // Every exact split of the bit into 8..25 quanta (1 sync + tseg1 1..16 +
  // tseg2 1..8), with the sample point nearest 87.5 % (CiA 301); on a tie the
  // finer quantum. SJW 1 quantum.
  if (bitrate == 0 || pclk_hz % bitrate != 0) return false;
  const std::uint32_t per_bit = pclk_hz / bitrate;  // clock cycles per bit
  bool found = false;
  std::uint32_t best_error = 0, best_scale = 1;             // the best sample point's error: best_error / best_scale
  for (std::uint32_t quanta = 25; quanta >= 8; --quanta) {  // finer quanta first: they win ties
    if (per_bit % quanta != 0) continue;
    const std::uint32_t prescaler = per_bit / quanta;
    if (prescaler > 1024) continue;
    for (std::uint32_t tseg2 = 1; tseg2 <= 8; ++tseg2) {
      if (quanta < tseg2 + 2) break;
      const std::uint32_t tseg1 = quanta - 1 - tseg2;
      if (tseg1 > 16) continue;
      // |(1 + tseg1) / quanta - 7/8| = error / (8 quanta)
      const std::uint32_t sample8 = 8 * (1 + tseg1), target8 = 7 * quanta;
      const std::uint32_t error = sample8 > target8 ? sample8 - target8 : target8 - sample8;
      const std::uint32_t scale = 8 * quanta;
      if (!found || static_cast<std::uint64_t>(error) * best_scale < static_cast<std::uint64_t>(best_error) * scale) {
        found = true;
        best_error = error;
        best_scale = scale;
        btr = ((tseg2 - 1) << 20U) | ((tseg1 - 1) << 16U) | (prescaler - 1);
      }
    }
  }
  return found;
}

bool BxCan::init(std::uint8_t node) {
  node_ = node;
  up_ = false;
  // CAN at 1 Mbit/s tolerates about 0.5 % of clock error; the 16 MHz internal
  // oscillator is only trimmed to 1 %. Without the crystal (it failed, or is
  // missing) the band stays off the bus rather than disturb it.
  if (!clocks().on_pll) {
    fault_ = CanFault::no_crystal;
    return false;
  }
  std::uint32_t btr = 0;
  if (!can_bit_timing(clocks().apb1_hz, kBitrate, btr)) {
    fault_ = CanFault::no_timing;
    return false;
  }
  rcc::ahb1enr.set(kGpioBEn);
  rcc::apb1enr.set(kCan1En);
  gpio::configure(gpio::kB, 8, 2, 9);             // CAN1_RX
  gpio::configure(gpio::kB, 9, 2, 9);             // CAN1_TX
  can1::mcr.write((1U << 6U) | (1U << 2U) | 1U);  // ABOM, TXFP, INRQ (leaves SLEEP)
  std::uint32_t spins = 100000;
  while ((can1::msr.read() & 1U) == 0 && --spins != 0) {
  }
  if (spins == 0) return retry_later();
  can1::btr.write(btr);
  // Filters 0 and 1, 32-bit mask mode, FIFO 0, data frames only: REQUEST
  // frames of every node, standard ids (0x600..0x61F) and extended ids at any
  // base (low 11 bits 0x600..0x61F). The core's reassembler picks its own node
  // and base, so a set_config that changes them needs no filter update.
  constexpr std::uint32_t kRequest = static_cast<std::uint32_t>(proto::can::Function::request);
  can1::fmr.set(1U);
  can1::fs1r.set(3U);
  can1::fm1r.clear(3U);
  can1::ffa1r.clear(3U);
  can1::f0r1.write(kRequest << 21U);
  can1::f0r2.write((0x7E0U << 21U) | (1U << 2U) | (1U << 1U));  // function bits, IDE, RTR must match
  can1::f1r1.write((kRequest << 3U) | (1U << 2U));              // EXID, IDE set
  can1::f1r2.write((0x7E0U << 3U) | (1U << 2U) | (1U << 1U));
  can1::fa1r.set(3U);
  can1::fmr.clear(1U);
  can1::mcr.clear(1U);
  spins = 100000;
  while ((can1::msr.read() & 1U) != 0 && --spins != 0) {
  }
  if (spins == 0) return retry_later();  // no bus: 11 recessive bits never seen
  can1::ier.write((1U << 1U) | 1U);      // FMPIE0, TMEIE
  nvic::priority(kIrqCan1Tx, 0x40);
  nvic::priority(kIrqCan1Rx0, 0x40);
  nvic::enable(kIrqCan1Tx);
  nvic::enable(kIrqCan1Rx0);
  fault_ = CanFault::none;
  up_ = true;
  return true;
}

bool BxCan::retry_later() {
  // No bus yet (unplugged, or the transceiver unpowered): try again later
  // from the main loop instead of staying off until the next reboot.
  fault_ = CanFault::no_bus;
  next_retry_us_ = micros() + kRetryUs;
  ++init_retries_;
  return false;
}

bool BxCan::ensure_up() {
  if (up_) return true;
  if (fault_ != CanFault::no_bus || micros() < next_retry_us_) return false;
  return init(node_);
}

bool BxCan::send(const proto::CanFrame& frame) {
  if (!ensure_up()) return false;
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
    can1::tdlr(mb).write(le32(&f.data[0]));
    can1::tdhr(mb).write(le32(&f.data[4]));
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

bool BxCan::idle() const { return !up_ || (tx_tail_ == tx_head_ && ((can1::tsr.read() >> 26U) & 7U) == 7U); }

bool BxCan::receive(proto::CanFrame& frame) {
  if (!ensure_up()) return false;
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

std::size_t FlashStorage::sector_count() const { return nvm_bytes() / kSectorSize; }

bool FlashStorage::read(std::size_t offset, std::span<std::uint8_t> out) {
  if (offset > size() || out.size() > size() - offset) return false;
  const volatile std::uint8_t* src = nvm_base() + offset;
  for (std::uint8_t& b : out) b = *src++;
  return true;
}

namespace {

constexpr std::uint32_t kFlashBusy = 1U << 16U, kFlashErrors = 0xF0U;  // PGSERR PGPERR PGAERR WRPERR
// FLASH_ACR: ICEN, DCEN, ICRST, DCRST
constexpr std::uint32_t kIcEn = 1U << 9U, kDcEn = 1U << 10U, kIcRst = 1U << 11U, kDcRst = 1U << 12U;

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

// After an erase or a program the ART caches may hold the old contents of
// the sector: reset them (RM0090 3.5.2: a cache is reset only while disabled).
void flush_flash_caches() {
  const std::uint32_t acr = flash::acr.read();
  flash::acr.write(acr & ~(kIcEn | kDcEn));
  flash::acr.write((acr & ~(kIcEn | kDcEn)) | kIcRst | kDcRst);
  flash::acr.write(acr & ~(kIcEn | kDcEn | kIcRst | kDcRst));
  flash::acr.write(acr & ~(kIcRst | kDcRst));
}

}  // namespace

bool FlashStorage::erase(std::size_t sector) {
  // The CPU stalls on instruction fetch for the erase (~250 ms): sample blocks
  // in that time are counted lost; the watchdog is set long enough.
  if (sector >= sector_count()) return false;
  flash_unlock();
  flash_wait();
  const auto snb = static_cast<std::uint32_t>(kFirstSector + sector);
  flash::cr.write((2U << 8U) | (snb << 3U) | (1U << 1U));  // PSIZE x32, SNB, SER
  flash::cr.set(1U << 16U);                                // STRT
  const bool ok = flash_wait();
  flash::cr.write(1U << 31U);  // lock
  flush_flash_caches();
  return ok;
}

bool FlashStorage::program(std::size_t offset, std::span<const std::uint8_t> data) {
  if (offset > size() || data.size() > size() - offset) return false;
  flash_unlock();
  bool ok = flash_wait();
  flash::cr.write(1U);  // PG, PSIZE x8
  volatile std::uint8_t* dst = nvm_base() + offset;
  for (std::size_t k = 0; k < data.size() && ok; ++k) {
    if (data[k] == 0xFF) continue;  // erased already
    dst[k] = data[k];
    ok = flash_wait();
  }
  flash::cr.write(1U << 31U);
  flush_flash_caches();
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

std::uint8_t NvicReset::boot_epoch() const {
  if (epoch_ == 0) {
    constexpr Reg kPwrCr{0x40007000};     // RM0090 5.4.1
    constexpr Reg kRtcBkp0r{0x40002850};  // RM0090 26.6.20, in the backup domain
    rcc::apb1enr.set(1U << 28U);          // PWREN
    kPwrCr.set(1U << 8U);                 // DBP: the backup domain is writable
    const std::uint32_t count = kRtcBkp0r.read() + 1U;
    kRtcBkp0r.write(count);
    epoch_ = static_cast<std::uint8_t>(count % 255U + 1U);
  }
  return epoch_;
}

void NvicReset::latch_reset_cause() {
  // RM0090 7.3.21. The pin flag is also set by every internal reset (they
  // drive NRST), so it counts only when nothing else is.
  const std::uint32_t csr = rcc::csr.read();
  const auto any = [csr](std::uint32_t bits) { return (csr & bits) != 0; };
  if (any((1U << 29U) | (1U << 30U))) {
    cause_ = proto::ResetCause::watchdog;  // IWDGRSTF, WWDGRSTF
  } else if (any(1U << 31U)) {
    cause_ = proto::ResetCause::low_power;  // LPWRRSTF
  } else if (any(1U << 28U)) {
    cause_ = proto::ResetCause::software;  // SFTRSTF
  } else if (any((1U << 27U) | (1U << 25U))) {
    cause_ = proto::ResetCause::power_on;  // PORRSTF, BORRSTF
  } else if (any(1U << 26U)) {
    cause_ = proto::ResetCause::pin;
  }
}

void NvicReset::enter_bootloader() { reboot_into_bootloader(); }

void NvicReset::reset() {
  dsb();
  scb::aircr.write((0x5FAU << 16U) | (1U << 2U));  // VECTKEY, SYSRESETREQ
  dsb();
  for (;;) {
  }
}

}  // namespace tonus::f405
