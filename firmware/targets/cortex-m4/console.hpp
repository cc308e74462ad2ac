// The band's text console on USART1 (115200 8N1, PB6): a boot line and a
// status line per second, for bring-up, the factory and the QEMU smoke test.
// Polled and allocation-free; numbers are formatted by hand (no printf).
#pragma once

#include <cstdint>

namespace tonus::f405::console {

void init();
void print(const char* text);
void print_u(std::uint64_t value);
void print_hex(std::uint64_t value);

}  // namespace tonus::f405::console
