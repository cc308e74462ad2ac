#include "tonus/protocol/hid_descriptor.hpp"

namespace tonus::proto::hid {

namespace {

enum class ItemType : std::uint8_t { main = 0, global = 1, local = 2, reserved = 3 };

// Item tags used here (HID 1.11, 6.2.2.4 - 6.2.2.8).
namespace tag {
inline constexpr std::uint8_t input = 0x8, output = 0x9, feature = 0xB, collection = 0xA, end_collection = 0xC;
inline constexpr std::uint8_t usage_page = 0x0, report_size = 0x7, report_id = 0x8, report_count = 0x9;
inline constexpr std::uint8_t push = 0xA, pop = 0xB;
inline constexpr std::uint8_t usage = 0x0;
}  // namespace tag

struct Globals {
  std::uint16_t usage_page = 0;
  std::uint32_t report_size = 0;
  std::uint32_t report_count = 0;
  std::uint8_t report_id = 0;
};

constexpr std::size_t kStackDepth = 8;
constexpr std::size_t kMaxCollectionDepth = 16;
constexpr std::uint32_t kMaxReportBits = 1U << 20U;  // far above any real report

Error add_bits(DescriptorInfo& info, std::uint8_t id, ReportType type, std::uint32_t bits) {
  for (std::size_t i = 0; i < info.report_count; ++i) {
    ReportInfo& r = info.reports[i];
    if (r.id == id && r.type == type) {
      if (r.bits + bits > kMaxReportBits) return Error::bad_length;
      r.bits += bits;
      return Error::ok;
    }
  }
  if (info.report_count == info.reports.size()) return Error::bad_length;
  info.reports[info.report_count++] = ReportInfo{id, type, bits};
  return Error::ok;
}

}  // namespace

std::size_t DescriptorInfo::report_bytes(std::uint8_t id, ReportType type) const {
  for (std::size_t i = 0; i < report_count; ++i) {
    if (reports[i].id == id && reports[i].type == type) {
      return (reports[i].bits + 7U) / 8U + (uses_report_ids ? 1U : 0U);
    }
  }
  return 0;
}

Error parse_report_descriptor(std::span<const std::uint8_t> desc, DescriptorInfo& out) {
  DescriptorInfo info{};
  Globals g{};
  std::array<Globals, kStackDepth> stack{};
  std::size_t stack_size = 0;
  std::size_t depth = 0;
  std::uint16_t last_usage = 0;
  bool seen_application = false;

  std::size_t pos = 0;
  while (pos < desc.size()) {
    const std::uint8_t prefix = desc[pos++];
    if (prefix == 0xFE) {  // long item: size, tag, data
      if (desc.size() - pos < 2) return Error::truncated;
      const std::size_t size = desc[pos];
      pos += 2;
      if (desc.size() - pos < size) return Error::truncated;
      pos += size;
      continue;
    }
    const std::size_t size_code = prefix & 0x3U;
    const std::size_t size = size_code == 3 ? 4 : size_code;
    const auto type = static_cast<ItemType>((prefix >> 2U) & 0x3U);
    const auto item_tag = static_cast<std::uint8_t>(prefix >> 4U);
    if (desc.size() - pos < size) return Error::truncated;
    std::uint32_t data = 0;
    for (std::size_t i = 0; i < size; ++i) data |= static_cast<std::uint32_t>(desc[pos + i]) << (8U * i);
    pos += size;

    switch (type) {
      case ItemType::main:
        if (item_tag == tag::input || item_tag == tag::output || item_tag == tag::feature) {
          if (depth == 0) return Error::bad_value;  // data items live inside a collection
          const ReportType rt = item_tag == tag::input    ? ReportType::input
                                : item_tag == tag::output ? ReportType::output
                                                          : ReportType::feature;
          const std::uint64_t bits = static_cast<std::uint64_t>(g.report_size) * g.report_count;
          if (bits > kMaxReportBits) return Error::bad_length;
          if (Error e = add_bits(info, g.report_id, rt, static_cast<std::uint32_t>(bits)); e != Error::ok) return e;
        } else if (item_tag == tag::collection) {
          if (++depth > kMaxCollectionDepth) return Error::bad_length;
          if (depth == 1 && !seen_application && data == 0x01) {
            seen_application = true;
            info.usage_page = g.usage_page;
            info.usage = last_usage;
          }
        } else if (item_tag == tag::end_collection) {
          if (depth == 0) return Error::bad_value;
          --depth;
        } else {
          return Error::bad_type;
        }
        break;
      case ItemType::global:
        if (item_tag == tag::usage_page) {
          g.usage_page = static_cast<std::uint16_t>(data);
        } else if (item_tag == tag::report_size) {
          g.report_size = data;
        } else if (item_tag == tag::report_count) {
          g.report_count = data;
        } else if (item_tag == tag::report_id) {
          if (data == 0 || data > 0xFF) return Error::bad_value;  // id 0 is reserved
          g.report_id = static_cast<std::uint8_t>(data);
          info.uses_report_ids = true;
        } else if (item_tag == tag::push) {
          if (stack_size == stack.size()) return Error::bad_length;
          stack[stack_size++] = g;
        } else if (item_tag == tag::pop) {
          if (stack_size == 0) return Error::bad_value;
          g = stack[--stack_size];
        }
        break;
      case ItemType::local:
        if (item_tag == tag::usage) last_usage = static_cast<std::uint16_t>(data);
        break;
      case ItemType::reserved: return Error::bad_type;
    }
  }
  if (depth != 0) return Error::truncated;  // unclosed collection
  if (!seen_application) return Error::bad_value;
  out = info;
  return Error::ok;
}

}  // namespace tonus::proto::hid
