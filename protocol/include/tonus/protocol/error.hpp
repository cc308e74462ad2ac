// Error codes returned by every encoder and decoder of the wire protocol.
#pragma once

#include <cstdint>

namespace tonus::proto {

enum class Error : std::uint8_t {
  ok = 0,
  truncated,         // input shorter than the message it announces
  bad_version,       // protocol major version this build does not speak
  bad_type,          // unknown report id, frame id, opcode or message kind
  bad_length,        // a length or count field is out of range
  bad_value,         // a field holds a value the protocol forbids
  bad_crc,           // checksum mismatch
  buffer_too_small,  // encoder output buffer cannot hold the message
  out_of_order,      // segment or frame arrived outside its expected place
};

constexpr const char* to_string(Error e) {
  switch (e) {
    case Error::ok: return "ok";
    case Error::truncated: return "truncated";
    case Error::bad_version: return "unsupported protocol version";
    case Error::bad_type: return "unknown message type";
    case Error::bad_length: return "length or count out of range";
    case Error::bad_value: return "field value out of range";
    case Error::bad_crc: return "checksum mismatch";
    case Error::buffer_too_small: return "output buffer too small";
    case Error::out_of_order: return "segment out of order";
  }
  return "unknown error";
}

}  // namespace tonus::proto
