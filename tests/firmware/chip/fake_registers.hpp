// A fake STM32F405 register file for host tests of the Cortex-M4 target's
// drivers (compiled with TONUS_FAKE_REGISTERS). Registers read back what was
// written unless a hook models the hardware: a ready flag that follows its
// enable bit, a counter, a FIFO. Writes are logged in order.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

namespace tonus::f405::fake {

struct RegisterFile {
  std::unordered_map<std::uint32_t, std::uint32_t> value;
  // Called on a read with the stored value; returns what the hardware shows.
  std::unordered_map<std::uint32_t, std::function<std::uint32_t(std::uint32_t)>> on_read;
  // Called on a write with (stored, written); returns what is stored.
  std::unordered_map<std::uint32_t, std::function<std::uint32_t(std::uint32_t, std::uint32_t)>> on_write;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> writes;  // (address, value) in order

  [[nodiscard]] std::uint32_t get(std::uint32_t address) const {
    const auto it = value.find(address);
    return it == value.end() ? 0U : it->second;
  }
  // Every value written to `address`, in order.
  [[nodiscard]] std::vector<std::uint32_t> written(std::uint32_t address) const {
    std::vector<std::uint32_t> out;
    for (const auto& [a, v] : writes) {
      if (a == address) out.push_back(v);
    }
    return out;
  }
};

// The file every fake access goes to; reset() clears it (and the fake flash).
RegisterFile& registers();
void reset();
// The fake flash behind hal::Storage (two 16 KiB sectors, erased).
std::vector<std::uint8_t>& nvm();

}  // namespace tonus::f405::fake
