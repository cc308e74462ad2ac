// Reading memory that may not exist, without a lockup: the read runs with a
// flag set, and the HardFault handler skips a faulting probe instruction and
// reports it instead of hanging. QEMU's STM32F405 has no system memory behind
// the unique id (0x1FFF7A10), and it does not implement CCR.BFHFNMIGN, so a
// fault-handler probe is the one way that works on the chip and under QEMU.
#pragma once

#include <cstdint>

namespace tonus::f405 {

// True and `value` if the word at `address` could be read.
bool probe_read(std::uint32_t address, std::uint32_t& value);

}  // namespace tonus::f405
