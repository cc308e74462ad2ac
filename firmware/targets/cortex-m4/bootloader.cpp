#include "bootloader.hpp"

#include <cstdint>

#include "registers.hpp"

namespace {

constexpr std::uint32_t kMagic = 0xB007DF0DU;
constexpr std::uint32_t kSystemMemory = 0x1FFF0000U;
__attribute__((section(".noinit"))) volatile std::uint32_t g_bootloader_request;

}  // namespace

namespace tonus::f405 {

void reboot_into_bootloader() {
  g_bootloader_request = kMagic;
  dsb();
  scb::aircr.write((0x5FAU << 16U) | (1U << 2U));  // VECTKEY, SYSRESETREQ
  dsb();
  for (;;) {
  }
}

}  // namespace tonus::f405

extern "C" void jump_to_bootloader_if_requested() {
  if (g_bootloader_request != kMagic) return;
  g_bootloader_request = 0;
  using namespace tonus::f405;
  rcc::apb2enr.set(1U << 14U);  // SYSCFGEN
  Reg{0x40013800}.write(1U);    // SYSCFG_MEMRMP: system memory at 0x00000000
  const auto* rom =
      reinterpret_cast<const volatile std::uint32_t*>(kSystemMemory);  // NOLINT(performance-no-int-to-ptr)
  const std::uint32_t stack = rom[0];
  const std::uint32_t entry = rom[1];
  asm volatile(
      "msr msp, %0\n\t"
      "bx %1\n\t" ::"r"(stack),
      "r"(entry)
      : "memory");
}
