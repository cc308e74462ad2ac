// Minimal parser for USB HID report descriptors (HID 1.11, section 6.2.2).
//
// Walks short items (main/global/local) and skips long items, tracking the
// global state (with push/pop) to total the bits of every report per id and
// type. Used to check our descriptor against the codec, and by the host to
// check a connected device's descriptor before trusting its reports.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "tonus/protocol/error.hpp"

namespace tonus::proto::hid {

enum class ReportType : std::uint8_t { input, output, feature };

struct ReportInfo {
  std::uint8_t id = 0;  // 0 when the descriptor uses no report ids
  ReportType type = ReportType::input;
  std::uint32_t bits = 0;
};

struct DescriptorInfo {
  static constexpr std::size_t kMaxReports = 16;
  std::uint16_t usage_page = 0;  // of the first application collection
  std::uint16_t usage = 0;
  bool uses_report_ids = false;
  std::array<ReportInfo, kMaxReports> reports{};
  std::size_t report_count = 0;

  // Size in bytes of a report as it travels (id byte included), 0 if absent.
  [[nodiscard]] std::size_t report_bytes(std::uint8_t id, ReportType type) const;
};

Error parse_report_descriptor(std::span<const std::uint8_t> desc, DescriptorInfo& out);

}  // namespace tonus::proto::hid
