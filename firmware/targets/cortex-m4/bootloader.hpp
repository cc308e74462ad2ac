// Reboot into the STM32F405's built-in USB DFU bootloader (AN2606: system
// memory at 0x1FFF0000), for firmware updates with `dfu-util`. A magic word
// in a RAM section the start-up code does not clear survives the system
// reset; the reset handler checks it before anything else and jumps with the
// chip still in its reset state, as the ROM bootloader expects.
#pragma once

namespace tonus::f405 {

// Marks the next boot for the bootloader and resets now.
[[noreturn]] void reboot_into_bootloader();

}  // namespace tonus::f405

// Called first thing by Reset_Handler: jumps to the ROM bootloader if asked.
extern "C" void jump_to_bootloader_if_requested();
