// The few STM32F405 registers the band uses, from RM0090 (rev 19). Written
// out here rather than vendored: Debian has no STM32 CMSIS device package.
#pragma once

#include <cstdint>

namespace tonus::f405 {

#if defined(TONUS_FAKE_REGISTERS)
// Host tests (tests/firmware/chip): every access goes to a fake register file
// whose hooks model the hardware's answers (ready flags, FIFOs, counters).
std::uint32_t fake_register_read(std::uint32_t address);
void fake_register_write(std::uint32_t address, std::uint32_t value);
struct Reg {
  std::uint32_t address;
  [[nodiscard]] std::uint32_t read() const { return fake_register_read(address); }
  void write(std::uint32_t v) const { fake_register_write(address, v); }
  void set(std::uint32_t bits) const { write(read() | bits); }
  void clear(std::uint32_t bits) const { write(read() & ~bits); }
};
// The CPU's side of the fake: interrupt masking and barriers are no-ops.
inline void disable_irq() {}
inline void enable_irq() {}
inline void dsb() {}
#else
struct Reg {
  std::uint32_t address;
  [[nodiscard]] volatile std::uint32_t& operator*() const {
    return *reinterpret_cast<volatile std::uint32_t*>(address);  // NOLINT(performance-no-int-to-ptr)
  }
  [[nodiscard]] std::uint32_t read() const { return **this; }
  void write(std::uint32_t v) const { **this = v; }
  void set(std::uint32_t bits) const { **this = **this | bits; }
  void clear(std::uint32_t bits) const { **this = **this & ~bits; }
};
inline void disable_irq() { asm volatile("cpsid i" ::: "memory"); }
inline void enable_irq() { asm volatile("cpsie i" ::: "memory"); }
inline void dsb() { asm volatile("dsb" ::: "memory"); }
#endif

constexpr Reg at(std::uint32_t base, std::uint32_t offset) { return Reg{base + offset}; }

// Core peripherals
namespace scb {
inline constexpr Reg icsr = {0xE000ED04};
inline constexpr Reg vtor = {0xE000ED08};
inline constexpr Reg aircr = {0xE000ED0C};
inline constexpr Reg ccr = {0xE000ED14};
inline constexpr Reg cfsr = {0xE000ED28};
inline constexpr Reg hfsr = {0xE000ED2C};
inline constexpr Reg cpacr = {0xE000ED88};
}  // namespace scb
namespace systick {
inline constexpr Reg ctrl = {0xE000E010};
inline constexpr Reg load = {0xE000E014};
inline constexpr Reg val = {0xE000E018};
}  // namespace systick
namespace nvic {
inline void enable(unsigned irq) { Reg{0xE000E100 + 4 * (irq / 32)}.write(1U << (irq % 32)); }
// IPR: one byte per interrupt, written as its aligned word (a read-modify-write).
inline void priority(unsigned irq, std::uint8_t prio) {
  const Reg ipr{0xE000E400 + 4 * (irq / 4)};
  const unsigned shift = 8 * (irq % 4);
  ipr.write((ipr.read() & ~(0xFFU << shift)) | (static_cast<std::uint32_t>(prio) << shift));
}
}  // namespace nvic

// IRQ numbers (RM0090 table 61)
inline constexpr unsigned kIrqCan1Tx = 19;
inline constexpr unsigned kIrqCan1Rx0 = 20;
inline constexpr unsigned kIrqDma2Stream0 = 56;
inline constexpr unsigned kIrqOtgFs = 67;

namespace rcc {
inline constexpr std::uint32_t kBase = 0x40023800;
inline constexpr Reg cr = at(kBase, 0x00);
inline constexpr Reg pllcfgr = at(kBase, 0x04);
inline constexpr Reg cfgr = at(kBase, 0x08);
inline constexpr Reg ahb1enr = at(kBase, 0x30);
inline constexpr Reg ahb2enr = at(kBase, 0x34);
inline constexpr Reg apb1enr = at(kBase, 0x40);
inline constexpr Reg apb2enr = at(kBase, 0x44);
inline constexpr Reg csr = at(kBase, 0x74);
}  // namespace rcc

namespace flash {
inline constexpr std::uint32_t kBase = 0x40023C00;
inline constexpr Reg acr = at(kBase, 0x00);
inline constexpr Reg keyr = at(kBase, 0x04);
inline constexpr Reg sr = at(kBase, 0x0C);
inline constexpr Reg cr = at(kBase, 0x10);
}  // namespace flash

namespace gpio {
inline constexpr std::uint32_t kA = 0x40020000, kB = 0x40020400, kC = 0x40020800;
inline constexpr Reg moder(std::uint32_t port) { return at(port, 0x00); }
inline constexpr Reg ospeedr(std::uint32_t port) { return at(port, 0x08); }
inline constexpr Reg bsrr(std::uint32_t port) { return at(port, 0x18); }
inline constexpr Reg afr(std::uint32_t port, unsigned pin) { return at(port, pin < 8 ? 0x20 : 0x24); }
// Sets a pin's mode (0 input, 1 output, 2 alternate, 3 analog) and alternate function.
inline void configure(std::uint32_t port, unsigned pin, unsigned mode, unsigned af = 0) {
  moder(port).write((moder(port).read() & ~(3U << (2 * pin))) | (mode << (2 * pin)));
  const unsigned shift = 4 * (pin % 8);
  afr(port, pin).write((afr(port, pin).read() & ~(0xFU << shift)) | (af << shift));
}
}  // namespace gpio

namespace usart1 {
inline constexpr std::uint32_t kBase = 0x40011000;
inline constexpr Reg sr = at(kBase, 0x00);
inline constexpr Reg dr = at(kBase, 0x04);
inline constexpr Reg brr = at(kBase, 0x08);
inline constexpr Reg cr1 = at(kBase, 0x0C);
}  // namespace usart1

namespace tim2 {
inline constexpr std::uint32_t kBase = 0x40000000;
inline constexpr Reg cr1 = at(kBase, 0x00);
inline constexpr Reg cr2 = at(kBase, 0x04);
inline constexpr Reg egr = at(kBase, 0x14);
inline constexpr Reg psc = at(kBase, 0x28);
inline constexpr Reg arr = at(kBase, 0x2C);
}  // namespace tim2

namespace adc1 {
inline constexpr std::uint32_t kBase = 0x40012000;
inline constexpr Reg sr = at(kBase, 0x00);
inline constexpr Reg cr1 = at(kBase, 0x04);
inline constexpr Reg cr2 = at(kBase, 0x08);
inline constexpr Reg smpr2 = at(kBase, 0x10);
inline constexpr Reg sqr1 = at(kBase, 0x2C);
inline constexpr Reg sqr2 = at(kBase, 0x30);
inline constexpr Reg sqr3 = at(kBase, 0x34);
inline constexpr Reg dr = at(kBase, 0x4C);
inline constexpr Reg ccr = {0x40012304};  // ADC common control
}  // namespace adc1

namespace dma2 {
inline constexpr std::uint32_t kBase = 0x40026400;
inline constexpr Reg lisr = at(kBase, 0x00);
inline constexpr Reg lifcr = at(kBase, 0x08);
// Stream 0 (ADC1 on channel 0)
inline constexpr Reg s0cr = at(kBase, 0x10);
inline constexpr Reg s0ndtr = at(kBase, 0x14);
inline constexpr Reg s0par = at(kBase, 0x18);
inline constexpr Reg s0m0ar = at(kBase, 0x1C);
inline constexpr Reg s0m1ar = at(kBase, 0x20);
inline constexpr Reg s0fcr = at(kBase, 0x24);
}  // namespace dma2

namespace can1 {
inline constexpr std::uint32_t kBase = 0x40006400;
inline constexpr Reg mcr = at(kBase, 0x000);
inline constexpr Reg msr = at(kBase, 0x004);
inline constexpr Reg tsr = at(kBase, 0x008);
inline constexpr Reg rf0r = at(kBase, 0x00C);
inline constexpr Reg ier = at(kBase, 0x014);
inline constexpr Reg esr = at(kBase, 0x018);
inline constexpr Reg btr = at(kBase, 0x01C);
inline constexpr Reg tir(unsigned mb) { return at(kBase, 0x180 + 0x10 * mb); }
inline constexpr Reg tdtr(unsigned mb) { return at(kBase, 0x184 + 0x10 * mb); }
inline constexpr Reg tdlr(unsigned mb) { return at(kBase, 0x188 + 0x10 * mb); }
inline constexpr Reg tdhr(unsigned mb) { return at(kBase, 0x18C + 0x10 * mb); }
inline constexpr Reg rir = at(kBase, 0x1B0);
inline constexpr Reg rdtr = at(kBase, 0x1B4);
inline constexpr Reg rdlr = at(kBase, 0x1B8);
inline constexpr Reg rdhr = at(kBase, 0x1BC);
inline constexpr Reg fmr = at(kBase, 0x200);
inline constexpr Reg fm1r = at(kBase, 0x204);
inline constexpr Reg fs1r = at(kBase, 0x20C);
inline constexpr Reg ffa1r = at(kBase, 0x214);
inline constexpr Reg fa1r = at(kBase, 0x21C);
inline constexpr Reg f0r1 = at(kBase, 0x240);
inline constexpr Reg f0r2 = at(kBase, 0x244);
inline constexpr Reg f1r1 = at(kBase, 0x248);
inline constexpr Reg f1r2 = at(kBase, 0x24C);
}  // namespace can1

// USB OTG full-speed core (RM0090 section 34.16), device mode.
namespace otg {
inline constexpr std::uint32_t kBase = 0x50000000;
inline constexpr Reg gahbcfg = at(kBase, 0x008);
inline constexpr Reg gusbcfg = at(kBase, 0x00C);
inline constexpr Reg grstctl = at(kBase, 0x010);
inline constexpr Reg gintsts = at(kBase, 0x014);
inline constexpr Reg gintmsk = at(kBase, 0x018);
inline constexpr Reg grxstsp = at(kBase, 0x020);
inline constexpr Reg grxfsiz = at(kBase, 0x024);
inline constexpr Reg dieptxf0 = at(kBase, 0x028);
inline constexpr Reg gccfg = at(kBase, 0x038);
inline constexpr Reg dieptxf1 = at(kBase, 0x104);
inline constexpr Reg dcfg = at(kBase, 0x800);
inline constexpr Reg dctl = at(kBase, 0x804);
inline constexpr Reg diepmsk = at(kBase, 0x810);
inline constexpr Reg doepmsk = at(kBase, 0x814);
inline constexpr Reg daint = at(kBase, 0x818);
inline constexpr Reg daintmsk = at(kBase, 0x81C);
inline constexpr Reg pcgcctl = at(kBase, 0xE00);
inline constexpr Reg diepctl(unsigned ep) { return at(kBase, 0x900 + 0x20 * ep); }
inline constexpr Reg diepint(unsigned ep) { return at(kBase, 0x908 + 0x20 * ep); }
inline constexpr Reg dieptsiz(unsigned ep) { return at(kBase, 0x910 + 0x20 * ep); }
inline constexpr Reg dtxfsts(unsigned ep) { return at(kBase, 0x918 + 0x20 * ep); }
inline constexpr Reg doepctl(unsigned ep) { return at(kBase, 0xB00 + 0x20 * ep); }
inline constexpr Reg doepint(unsigned ep) { return at(kBase, 0xB08 + 0x20 * ep); }
inline constexpr Reg doeptsiz(unsigned ep) { return at(kBase, 0xB10 + 0x20 * ep); }
inline constexpr Reg fifo(unsigned ep) { return at(kBase, 0x1000 + 0x1000 * ep); }
}  // namespace otg

namespace iwdg {
inline constexpr std::uint32_t kBase = 0x40003000;
inline constexpr Reg kr = at(kBase, 0x00);
inline constexpr Reg pr = at(kBase, 0x04);
inline constexpr Reg rlr = at(kBase, 0x08);
}  // namespace iwdg

}  // namespace tonus::f405
