// A small reader for the subset of the Vector DBC format that tonus.dbc uses
// (BO_ and SG_ lines), so tests can check the file against the codec.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace tonus::test {

struct DbcSignal {
  std::string name;
  unsigned start_bit = 0;
  unsigned length = 0;
  bool little_endian = true;  // "@1" (Intel)
  bool is_signed = false;
  double factor = 1.0;
  double offset = 0.0;

  // Raw value of the signal in a frame's data (Intel byte order only).
  [[nodiscard]] std::uint64_t raw(std::span<const std::uint8_t> data) const;
};

struct DbcMessage {
  std::uint32_t id = 0;
  std::string name;
  unsigned dlc = 0;
  std::vector<DbcSignal> signals;
};

std::vector<DbcMessage> read_dbc(const std::string& path);

}  // namespace tonus::test
