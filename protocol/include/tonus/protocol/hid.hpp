// USB-HID binding: one message per 64-byte report, report id first.
//
//   id 0x01  Input   stiffness stream (StreamMessage)
//   id 0x02  Output  command request
//   id 0x03  Input   command response
// Each report is 1 id byte + 63 payload bytes; the message sits at the front of
// the payload and the rest is zero padding. The descriptor declares a vendor
// usage page (0xFF00), so no OS driver claims the band; hidapi/hidraw read it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "tonus/protocol/command.hpp"
#include "tonus/protocol/error.hpp"
#include "tonus/protocol/limits.hpp"
#include "tonus/protocol/stream.hpp"

namespace tonus::proto::hid {

inline constexpr std::uint16_t kUsagePage = 0xFF00;
inline constexpr std::uint8_t kReportIdStream = 0x01;
inline constexpr std::uint8_t kReportIdCommand = 0x02;
inline constexpr std::uint8_t kReportIdResponse = 0x03;
inline constexpr std::size_t kReportSize = 64;                  // bytes on the wire, id included
inline constexpr std::size_t kReportPayload = kReportSize - 1;  // 63
static_assert(kReportPayload == kMaxMessageSize);

using Report = std::array<std::uint8_t, kReportSize>;

// clang-format off
inline constexpr auto kReportDescriptor = std::to_array<std::uint8_t>({
  0x06, 0x00, 0xFF,  // Usage Page (Vendor Defined 0xFF00)
  0x09, 0x01,        // Usage (0x01: tonus band)
  0xA1, 0x01,        // Collection (Application)
  0x15, 0x00,        //   Logical Minimum (0)
  0x26, 0xFF, 0x00,  //   Logical Maximum (255)
  0x75, 0x08,        //   Report Size (8)
  0x95, 0x3F,        //   Report Count (63)
  0x85, 0x01,        //   Report ID (1)
  0x09, 0x02,        //   Usage (0x02: stiffness stream)
  0x81, 0x02,        //   Input (Data, Variable, Absolute)
  0x85, 0x02,        //   Report ID (2)
  0x09, 0x03,        //   Usage (0x03: command)
  0x91, 0x02,        //   Output (Data, Variable, Absolute)
  0x85, 0x03,        //   Report ID (3)
  0x09, 0x04,        //   Usage (0x04: response)
  0x81, 0x02,        //   Input (Data, Variable, Absolute)
  0xC0,              // End Collection
});
// clang-format on

// Builds a full report (id + message + zero padding).
Error pack_stream(const StreamMessage& msg, Report& out);
Error pack_request(const Request& req, Report& out);
Error pack_response(const Response& rsp, Report& out);

// Decodes a report as read from hidraw/hidapi (id first). `report` may be
// shorter than 64 bytes if the OS strips padding; longer is bad_length; a
// report id other than the expected one is bad_type.
Error unpack_stream(std::span<const std::uint8_t> report, StreamMessage& out);
Error unpack_request(std::span<const std::uint8_t> report, Request& out);
Error unpack_response(std::span<const std::uint8_t> report, Response& out);

}  // namespace tonus::proto::hid
