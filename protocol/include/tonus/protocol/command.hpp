// Command requests (host -> device) and responses (device -> host).
//
// Request:  0 u8 version | 1 u8 opcode | 2 u8 token | 3 u8 length | 4.. payload | u16 crc
// Response: 0 u8 version | 1 u8 opcode|0x80 | 2 u8 token | 3 u8 status | 4 u8 length
//           | 5.. payload | u16 crc
// The CRC is CRC-16/CCITT-FALSE over every byte before it. The token is
// chosen by the host and echoed so that responses match requests.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "tonus/protocol/error.hpp"
#include "tonus/protocol/limits.hpp"

namespace tonus::proto {

enum class Opcode : std::uint8_t {
  get_device_info = 0x01,
  time_sync = 0x02,
  get_stats = 0x03,
  get_log = 0x04,  // minor 1: the device's fault log
  calibration_start = 0x10,
  calibration_abort = 0x11,
  calibration_status = 0x12,
  get_config = 0x20,
  set_config = 0x21,
  save_config = 0x22,
  reset = 0x30,
  enter_bootloader = 0x31,  // minor 1: reboot into the update bootloader (DFU)
};

bool is_known(Opcode op);

// Outcome of a command, carried in every response.
enum class Status : std::uint8_t {
  ok = 0,
  unknown_opcode = 1,
  bad_length = 2,     // payload shorter than the opcode needs
  bad_value = 3,      // a field is out of range; nothing was changed
  busy = 4,           // try again later (e.g. NVM write in progress)
  wrong_state = 5,    // not allowed now (e.g. abort with no calibration running)
  storage_error = 6,  // NVM write or verify failed
  bad_version = 7,    // request carried another protocol major version
  bad_crc = 8,        // request failed its checksum
};

const char* to_string(Status s);

inline constexpr std::size_t kRequestOverhead = 4 + 2;
inline constexpr std::size_t kResponseOverhead = 5 + 2;
inline constexpr std::size_t kMaxRequestPayload = kMaxMessageSize - kRequestOverhead;    // 57
inline constexpr std::size_t kMaxResponsePayload = kMaxMessageSize - kResponseOverhead;  // 56
inline constexpr std::uint8_t kResponseBit = 0x80;

struct Request {
  Opcode opcode = Opcode::get_device_info;
  std::uint8_t token = 0;
  std::uint8_t length = 0;
  std::array<std::uint8_t, kMaxRequestPayload> payload{};

  [[nodiscard]] std::span<const std::uint8_t> body() const { return {payload.data(), length}; }
  friend bool operator==(const Request&, const Request&) = default;
};

struct Response {
  Opcode opcode = Opcode::get_device_info;
  std::uint8_t token = 0;
  Status status = Status::ok;
  std::uint8_t length = 0;
  std::array<std::uint8_t, kMaxResponsePayload> payload{};

  [[nodiscard]] std::span<const std::uint8_t> body() const { return {payload.data(), length}; }
  friend bool operator==(const Response&, const Response&) = default;
};

// Encoders refuse lengths over capacity. Decoders read from the front of `in`
// (trailing padding ignored), check version, length and CRC. Unknown opcodes
// decode fine so that the device can answer them with Status::unknown_opcode;
// unknown status codes in a response are a decode error.
Error encode_request(const Request& req, std::span<std::uint8_t> out, std::size_t& written);
Error decode_request(std::span<const std::uint8_t> in, Request& out);
Error encode_response(const Response& rsp, std::span<std::uint8_t> out, std::size_t& written);
Error decode_response(std::span<const std::uint8_t> in, Response& out);

}  // namespace tonus::proto
