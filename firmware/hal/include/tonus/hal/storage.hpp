// HAL: non-volatile storage with flash semantics: erase sets the whole area
// to 0xFF, program may only write bytes that are erased. On the band this is
// one 16 KiB flash sector; the core keeps an append-only record log in it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace tonus::hal {

class Storage {
 public:
  [[nodiscard]] virtual std::size_t size() const = 0;
  virtual bool read(std::size_t offset, std::span<std::uint8_t> out) = 0;
  virtual bool erase() = 0;
  virtual bool program(std::size_t offset, std::span<const std::uint8_t> data) = 0;

 protected:
  ~Storage() = default;
};

}  // namespace tonus::hal
