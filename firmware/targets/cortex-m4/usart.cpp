#include "usart.hpp"

#include "clock.hpp"
#include "registers.hpp"

namespace tonus::f405::usart {

void init(std::uint32_t baud) {
  rcc::ahb1enr.set(1U << 1U);  // GPIOB
  rcc::apb2enr.set(1U << 4U);  // USART1
  gpio::configure(gpio::kB, 6, 2, 7);
  usart1::brr.write((clocks().apb2_hz + baud / 2U) / baud);  // oversampling by 16
  usart1::cr1.write((1U << 13U) | (1U << 3U));               // UE, TE
}

void write(std::span<const std::uint8_t> bytes) {
  for (std::uint8_t b : bytes) {
    std::uint32_t spins = 100000;
    while ((usart1::sr.read() & (1U << 7U)) == 0 && --spins != 0) {  // TXE
    }
    usart1::dr.write(b);
  }
}

}  // namespace tonus::f405::usart
