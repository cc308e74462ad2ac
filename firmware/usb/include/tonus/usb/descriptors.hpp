// USB descriptors of the band: one configuration, one HID interface (vendor
// usage page, the report descriptor of tonus::proto::hid), EP1 IN and OUT as
// 64-byte interrupt endpoints polled every 1 ms (full speed).
//
// VID 0x1209 is pid.codes' open-source vendor id; PID 0x0001 is their test
// PID, for development only: a production band needs its own PID.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "tonus/protocol/hid.hpp"

namespace tonus::usb {

inline constexpr std::uint16_t kVendorId = 0x1209;
inline constexpr std::uint16_t kProductId = 0x0001;
inline constexpr std::uint16_t kDeviceRelease = 0x0050;  // BCD, firmware 0.5

namespace desc {
inline constexpr std::uint8_t device = 1, configuration = 2, string = 3, interface = 4, endpoint = 5;
inline constexpr std::uint8_t hid = 0x21, hid_report = 0x22;
}  // namespace desc

inline constexpr std::size_t kReportDescriptorSize = proto::hid::kReportDescriptor.size();

// clang-format off
inline constexpr std::array<std::uint8_t, 18> kDeviceDescriptor = {
  18, desc::device,
  0x00, 0x02,          // bcdUSB 2.00
  0x00, 0x00, 0x00,    // class per interface
  64,                  // bMaxPacketSize0
  kVendorId & 0xFF, kVendorId >> 8,
  kProductId & 0xFF, kProductId >> 8,
  kDeviceRelease & 0xFF, kDeviceRelease >> 8,
  1, 2, 3,             // manufacturer, product, serial strings
  1,                   // one configuration
};

inline constexpr std::size_t kConfigurationSize = 9 + 9 + 9 + 7 + 7;
inline constexpr std::array<std::uint8_t, kConfigurationSize> kConfigurationDescriptor = {
  9, desc::configuration, kConfigurationSize, 0, 1, 1, 0,
  0x80,                // bus powered
  50,                  // 100 mA
  // interface 0: HID, no boot protocol, two endpoints
  9, desc::interface, 0, 0, 2, 0x03, 0x00, 0x00, 0,
  // HID 1.11, one report descriptor
  9, desc::hid, 0x11, 0x01, 0, 1, desc::hid_report,
  static_cast<std::uint8_t>(kReportDescriptorSize & 0xFF), static_cast<std::uint8_t>(kReportDescriptorSize >> 8),
  // EP1 IN, interrupt, 64 bytes, 1 ms
  7, desc::endpoint, 0x81, 0x03, 64, 0, 1,
  // EP1 OUT, interrupt, 64 bytes, 1 ms
  7, desc::endpoint, 0x01, 0x03, 64, 0, 1,
};
// clang-format on

// String descriptor k (0 = languages) into `out`; returns its size, 0 if there is none.
// The serial string is the 64-bit serial number in 16 hex digits.
std::size_t string_descriptor(std::uint8_t index, std::uint64_t serial, std::span<std::uint8_t> out);

}  // namespace tonus::usb
