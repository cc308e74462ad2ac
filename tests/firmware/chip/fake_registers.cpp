#include "fake_registers.hpp"

#include <cstdlib>

#include "bootloader.hpp"
#include "registers.hpp"

namespace tonus::f405 {

namespace fake {

RegisterFile& registers() {
  static RegisterFile file;
  return file;
}

std::vector<std::uint8_t>& nvm() {
  static std::vector<std::uint8_t> bytes(std::size_t{32} * 1024, 0xFF);
  return bytes;
}

void reset() {
  registers() = RegisterFile{};
  std::fill(nvm().begin(), nvm().end(), std::uint8_t{0xFF});
}

}  // namespace fake

std::uint32_t fake_register_read(std::uint32_t address) {
  const fake::RegisterFile& f = fake::registers();
  const std::uint32_t stored = f.get(address);
  const auto hook = f.on_read.find(address);
  return hook == f.on_read.end() ? stored : hook->second(stored);
}

void fake_register_write(std::uint32_t address, std::uint32_t v) {
  fake::RegisterFile& f = fake::registers();
  f.writes.emplace_back(address, v);
  const auto hook = f.on_write.find(address);
  f.value[address] = hook == f.on_write.end() ? v : hook->second(f.get(address), v);
}

std::span<std::uint8_t> fake_nvm_area() { return fake::nvm(); }

}  // namespace tonus::f405

namespace tonus::f405 {

// The jump into the ROM bootloader cannot run on the host; no test reaches it.
void reboot_into_bootloader() { std::abort(); }

}  // namespace tonus::f405
