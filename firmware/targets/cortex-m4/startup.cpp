// Start-up code of the band: vector table, reset handler (.data copy, .bss
// clear, FPU enable, static constructors, clock tree) and default handlers.
// No C library start-up files are linked (-nostartfiles).
#include <cstdint>

#include "bootloader.hpp"
#include "clock.hpp"
#include "registers.hpp"

extern "C" {
extern std::uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
extern void (*__init_array_start[])();
extern void (*__init_array_end[])();
// The image's entry point (C++ forbids calling main, and no C runtime calls it here).
void firmware_main();

void Reset_Handler();
void Default_Handler();
void HardFault_Handler();
// Weak aliases: a driver defines the handlers it needs.
void NMI_Handler() __attribute__((weak, alias("Default_Handler")));
void MemManage_Handler() __attribute__((weak, alias("Default_Handler")));
void BusFault_Handler() __attribute__((weak, alias("Default_Handler")));
void UsageFault_Handler() __attribute__((weak, alias("Default_Handler")));
void SVC_Handler() __attribute__((weak, alias("Default_Handler")));
void DebugMon_Handler() __attribute__((weak, alias("Default_Handler")));
void PendSV_Handler() __attribute__((weak, alias("Default_Handler")));
void SysTick_Handler() __attribute__((weak, alias("Default_Handler")));
void CAN1_TX_IRQHandler() __attribute__((weak, alias("Default_Handler")));
void CAN1_RX0_IRQHandler() __attribute__((weak, alias("Default_Handler")));
void DMA2_Stream0_IRQHandler() __attribute__((weak, alias("Default_Handler")));
void OTG_FS_IRQHandler() __attribute__((weak, alias("Default_Handler")));

// A pure virtual call is a bug; stop here rather than pull in libsupc++'s
// terminate machinery (which would allocate).
void __cxa_pure_virtual() {
  for (;;) {
  }
}
}

namespace {

using Handler = void (*)();
constexpr unsigned kIrqCount = 82;  // STM32F405: IRQ 0..81

struct VectorTable {
  std::uint32_t* initial_sp;
  Handler system[15];
  Handler irq[kIrqCount];
};

constexpr VectorTable make_table() {
  VectorTable t{};
  t.initial_sp = &_estack;
  t.system[0] = Reset_Handler;
  t.system[1] = NMI_Handler;
  t.system[2] = HardFault_Handler;
  t.system[3] = MemManage_Handler;
  t.system[4] = BusFault_Handler;
  t.system[5] = UsageFault_Handler;
  t.system[10] = SVC_Handler;
  t.system[11] = DebugMon_Handler;
  t.system[13] = PendSV_Handler;
  t.system[14] = SysTick_Handler;
  for (Handler& h : t.irq) h = Default_Handler;
  t.irq[tonus::f405::kIrqCan1Tx] = CAN1_TX_IRQHandler;
  t.irq[tonus::f405::kIrqCan1Rx0] = CAN1_RX0_IRQHandler;
  t.irq[tonus::f405::kIrqDma2Stream0] = DMA2_Stream0_IRQHandler;
  t.irq[tonus::f405::kIrqOtgFs] = OTG_FS_IRQHandler;
  return t;
}

}  // namespace

__attribute__((section(".isr_vector"), used)) const VectorTable g_vectors = make_table();

extern "C" __attribute__((section(".text.Reset_Handler"), noreturn)) void Reset_Handler() {
  jump_to_bootloader_if_requested();  // a firmware update asked for the ROM bootloader
  // The FPU first: the compiler may use VFP registers anywhere after this.
  tonus::f405::scb::cpacr.set(0xFU << 20U);  // CP10, CP11 full access
  asm volatile("dsb\n\tisb" ::: "memory");
  const std::uint32_t* src = &_sidata;
  for (std::uint32_t* dst = &_sdata; dst < &_edata;) *dst++ = *src++;
  for (std::uint32_t* dst = &_sbss; dst < &_ebss;) *dst++ = 0;
  tonus::f405::clock_init();
  for (auto* f = __init_array_start; f < __init_array_end; ++f) (*f)();
  firmware_main();
  for (;;) {
  }
}

extern "C" void Default_Handler() {
  // An unexpected interrupt: hang so the watchdog resets the band.
  for (;;) {
  }
}

// Passes the stacked frame (MSP or PSP, from EXC_RETURN bit 2) to
// hard_fault_dispatch (probe.cpp), which returns from the exception itself.
extern "C" __attribute__((naked)) void HardFault_Handler() {
  asm volatile(
      "tst lr, #4\n\t"
      "ite eq\n\t"
      "mrseq r0, msp\n\t"
      "mrsne r0, psp\n\t"
      "b hard_fault_dispatch\n\t");
}
