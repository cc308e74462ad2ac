// The candump log format of can-utils (`candump -l`, read by canplayer and
// log2asc): one frame per line, "(seconds.micros) iface id#data".
//   (1700000000.000123) can0 101#0102030405060708
// Standard ids have 3 hex digits, extended ids 8; "#R" marks a remote frame;
// CAN FD ("##") is not part of this protocol and is reported as bad_type.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "tonus/protocol/can.hpp"
#include "tonus/protocol/error.hpp"

namespace tonus::proto::candump {

inline constexpr std::size_t kMaxIfaceName = 15;  // IFNAMSIZ - 1
// "(" 20-digit seconds "." 6 digits ") " iface " " 8 id "#" 16 data "\n"
inline constexpr std::size_t kMaxLine = 1 + 20 + 1 + 6 + 2 + kMaxIfaceName + 1 + 8 + 1 + 16 + 1;

struct Record {
  std::uint64_t time_us = 0;
  std::array<char, kMaxIfaceName + 1> iface{};  // NUL-terminated
  CanFrame frame{};

  [[nodiscard]] std::string_view iface_name() const;
  friend bool operator==(const Record&, const Record&) = default;
};

// Sets the interface name; false (name unchanged) if empty, too long or with spaces.
bool set_iface(Record& rec, std::string_view name);

// Formats one line, newline included, into `out`.
Error format(const Record& rec, std::span<char> out, std::size_t& written);

// Parses one line (a trailing "\n" or "\r\n" is allowed).
Error parse(std::string_view line, Record& out);

}  // namespace tonus::proto::candump
