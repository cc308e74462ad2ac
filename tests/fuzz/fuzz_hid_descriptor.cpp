// HID report descriptor parser (the host runs it on whatever a connected
// device claims): never crash, never report an impossible report size.
#include <cstddef>
#include <cstdint>
#include <span>

#include "fuzz_check.hpp"
#include "tonus/protocol/hid_descriptor.hpp"

using namespace tonus::proto;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  hid::DescriptorInfo info{};
  if (hid::parse_report_descriptor(std::span(data, size), info) == Error::ok) {
    TONUS_FUZZ_CHECK(info.report_count <= hid::DescriptorInfo::kMaxReports);
    for (std::size_t i = 0; i < info.report_count; ++i) {
      TONUS_FUZZ_CHECK(info.reports[i].bits <= (1U << 20U));
      TONUS_FUZZ_CHECK(info.report_bytes(info.reports[i].id, info.reports[i].type) > 0 || info.reports[i].bits == 0);
    }
  }
  return 0;
}
