// USART1 transmitter (PB6 TX, AF7), polled: the self-test streams COBS-framed
// protocol messages on it. 115200 baud 8N1 from APB2.
#pragma once

#include <cstdint>
#include <span>

namespace tonus::f405::usart {

void init(std::uint32_t baud);
void write(std::span<const std::uint8_t> bytes);

}  // namespace tonus::f405::usart
