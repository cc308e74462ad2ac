// HAL: non-volatile storage with flash semantics, in equal erase sectors:
// erasing a sector sets it to 0xFF, program may only clear bits. On the band
// these are two 16 KiB flash sectors; the core keeps its record log in them so
// that one sector always holds a valid copy while the other is erased.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace tonus::hal {

class Storage {
 public:
  [[nodiscard]] virtual std::size_t sector_size() const = 0;
  [[nodiscard]] virtual std::size_t sector_count() const = 0;
  [[nodiscard]] std::size_t size() const { return sector_size() * sector_count(); }
  // Offsets run over the whole area: sector s starts at s * sector_size().
  virtual bool read(std::size_t offset, std::span<std::uint8_t> out) = 0;
  virtual bool erase(std::size_t sector) = 0;
  virtual bool program(std::size_t offset, std::span<const std::uint8_t> data) = 0;

 protected:
  ~Storage() = default;
};

}  // namespace tonus::hal
